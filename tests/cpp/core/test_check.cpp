// The one geometry check (check::geometry, scattering/geometry.hpp).
#include <cmath>
#include <string>

#include <gtest/gtest.h>

#include "roughscope/core/errors.hpp"
#include "roughscope/scattering/geometry.hpp"

using namespace roughscope;

TEST(CheckGeometry, AcceptsThePaperRange) {
    EXPECT_NO_THROW(check::geometry({0.0, deg_to_rad(89.9), 7.0 * kPi}));
    EXPECT_NO_THROW(check::geometry({0.3, 0.2, -1.0}, "geom1"));
}

TEST(CheckGeometry, NamesTheAngleAndTheGeometry) {
    try {
        check::geometry({0.1, deg_to_rad(95.0), 0.0}, "geom2");
        FAIL() << "no exception";
    } catch (const InvalidArgument& e) {
        const std::string m = e.what();
        EXPECT_NE(m.find("geom2 theta_s = 95"), std::string::npos) << m;
        EXPECT_NE(m.find("[0, 90)"), std::string::npos) << m;
    }
    EXPECT_THROW(check::geometry({-0.1, 0.0, 0.0}), InvalidArgument);
    EXPECT_THROW(check::geometry({0.1, 0.0, std::nan("")}), InvalidArgument);
    EXPECT_THROW(check::geometry({kPi / 2, 0.0, 0.0}), InvalidArgument);
}
