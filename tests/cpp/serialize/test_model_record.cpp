// The records of `roughscope model` (roughscope/serialize/model.hpp): a ModelRecord's JSON object,
// its CSV text, and ModelRecordWriter's streamed JSON array and CSV, which must be the bytes that
// dump() of the whole versioned array and model_record_csv() give.
#include <cmath>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <limits>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "roughscope/core/errors.hpp"
#include "roughscope/io/output_file.hpp"
#include "roughscope/serialize/model.hpp"

using namespace roughscope;
using serialize::Json;
using serialize::ModelRecord;

namespace {

constexpr int kDigits = 10;

std::string read_file(const std::filesystem::path& path) {
    std::ifstream in(path, std::ios::binary);
    return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

// Row k of a small table: the kinds of value a model record holds.
void fill(ModelRecord& r, int k) {
    r.clear();
    r["model"] = "bk";
    r["theta_i_deg"] = ModelRecord::NumberOrNull{10.0 * k};
    r["visible"] = k % 2 == 0;
    r["brightness"] = ModelRecord::NumberOrNull{1.0 / (k + 3)};
    r["g"] = ModelRecord::NumberOrNull{std::nullopt};
    r["sigma_um"] = ModelRecord::NumberOrNull{std::numeric_limits<double>::quiet_NaN()};
    r["note"] = k == 2 ? "needs, \"quoting\"" : "plain";
}

// Writes the records 0..count-1 through a ModelRecordWriter into a file and returns its bytes.
std::string written(bool json_output, int count, const std::filesystem::path& path) {
    io::OutputFile out(path);
    serialize::ModelRecordWriter writer(out, json_output, kDigits);
    ModelRecord r;
    for (int k = 0; k < count; ++k) {
        fill(r, k);
        writer.add(r);
    }
    EXPECT_EQ(writer.count(), static_cast<std::size_t>(count));
    writer.finish();
    out.commit();
    return read_file(path);
}

class ModelRecordWriterTest : public ::testing::Test {
  protected:
    void SetUp() override {
        path_ = std::filesystem::temp_directory_path() /
                ("roughscope_model_record_" +
                 std::to_string(::testing::UnitTest::GetInstance()->random_seed()) + "_" +
                 ::testing::UnitTest::GetInstance()->current_test_info()->name());
    }
    void TearDown() override { std::filesystem::remove(path_); }
    std::filesystem::path path_;
};

}  // namespace

TEST(ModelRecord, ToJsonKeepsKeyOrderAndNullForUnknown) {
    ModelRecord r;
    fill(r, 1);
    const Json j = r.to_json();
    std::vector<std::string> keys;
    for (const auto& [key, value] : j.items()) keys.push_back(key);
    EXPECT_EQ(keys, (std::vector<std::string>{"model", "theta_i_deg", "visible", "brightness", "g",
                                              "sigma_um", "note"}));
    EXPECT_EQ(j["theta_i_deg"], 10.0);
    EXPECT_EQ(j["visible"], false);
    EXPECT_TRUE(j["g"].is_null());
    EXPECT_TRUE(j["sigma_um"].is_null());  // NaN is never a result
}

TEST(ModelRecord, ReusedRecordForgetsThePreviousRow) {
    ModelRecord r;
    fill(r, 0);
    r["extra"] = "only in row 0";
    fill(r, 1);
    EXPECT_FALSE(r.contains("extra"));
    EXPECT_EQ(r.to_json().size(), 7U);
}

TEST(ModelRecord, CsvTextQuotesOnlyWhatNeedsIt) {
    ModelRecord r;
    fill(r, 2);
    EXPECT_EQ(serialize::model_record_csv(r.to_json(), kDigits),
              "model,theta_i_deg,visible,brightness,g,sigma_um,note\n"
              "bk,20,true,0.2,,,\"needs, \"\"quoting\"\"\"\n");
}

TEST(ModelRecord, CellTextOfNonFiniteNumberIsAnError) {
    EXPECT_THROW(serialize::model_cell_text(Json(std::numeric_limits<double>::infinity()), 6),
                 Error);
    EXPECT_EQ(serialize::model_cell_text(Json(1.0 / 3.0), 6), "0.333333");
    EXPECT_EQ(serialize::model_cell_text(Json(nullptr), 6), "");
}

TEST_F(ModelRecordWriterTest, JsonIsTheDumpOfTheVersionedArray) {
    Json all = Json::array();
    ModelRecord r;
    for (int k = 0; k < 4; ++k) {
        fill(r, k);
        all.push_back(r.to_json());
    }
    // Record 2 holds a string to escape: the writer's slow path in the middle of its fast one.
    EXPECT_EQ(written(true, 4, path_), serialize::dump(serialize::versioned(all)));
}

TEST_F(ModelRecordWriterTest, CsvIsTheHeaderOnceAndOneLinePerRecord) {
    std::string expected;
    ModelRecord r;
    for (int k = 0; k < 3; ++k) {
        fill(r, k);
        const std::string text = serialize::model_record_csv(r.to_json(), kDigits);
        expected += k == 0 ? text : text.substr(text.find('\n') + 1);
    }
    EXPECT_EQ(written(false, 3, path_), expected);
}

TEST_F(ModelRecordWriterTest, NoRecordsWriteNothing) {
    EXPECT_EQ(written(true, 0, path_), "");
    EXPECT_EQ(written(false, 0, path_), "");
}
