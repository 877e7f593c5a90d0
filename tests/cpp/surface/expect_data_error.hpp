// Test helper of the height-file tests: `body` must throw DataError whose message contains every
// one of `parts` (the file name, the line or offset, the rule broken).
#pragma once

#include <initializer_list>
#include <string>

#include <gtest/gtest.h>

#include "roughscope/core/errors.hpp"

namespace roughscope::testing {

template <class Body>
void expect_data_error(Body&& body, std::initializer_list<const char*> parts) {
    try {
        body();
        ADD_FAILURE() << "no DataError";
    } catch (const DataError& e) {
        for (const char* part : parts) {
            EXPECT_NE(std::string(e.what()).find(part), std::string::npos)
                << "'" << part << "' not in: " << e.what();
        }
    }
}

}  // namespace roughscope::testing
