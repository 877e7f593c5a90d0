// The typed JSON reader of the input documents (src/io/json_reader.hpp): every getter names the
// document and the key path, with the valid range; files and arguments give their own error type.
#include <filesystem>
#include <fstream>
#include <limits>
#include <string>

#include <gtest/gtest.h>

#include "io/json_reader.hpp"
#include "roughscope/core/errors.hpp"

namespace roughscope::io {
namespace {

template <class E = DataError, class F>
std::string error_of(F f) {
    try {
        f();
    } catch (const E& e) {
        return e.what();
    }
    return "no error";
}

const JsonValue kDoc = JsonValue::parse(R"({
    "captures": [{"theta_i_deg": 30, "image": "a.png"}, {"theta_i_deg": "30", "n": 2.5}],
    "gamma": 2.2, "count": 3, "flag": true, "none": null, "big": 18446744073709551615,
    "pair": [1, 2]
})");

TEST(JsonReader, TypedValuesNameTheFileAndTheKeyPath) {
    const JsonNode doc(kDoc, "c.json");
    EXPECT_EQ(doc.at("captures").item(0).at("theta_i_deg").number(0.0, 90.0), 30.0);
    EXPECT_EQ(doc.at("captures").item(0).at("image").string(), "a.png");
    EXPECT_EQ(doc.at("count").integer(1, 10), 3);
    EXPECT_TRUE(doc.at("flag").boolean());
    EXPECT_EQ(doc.at("pair").numbers(2)[1], 2.0);
    EXPECT_EQ(doc.at("captures").item(1).path(), "captures[1]");
    EXPECT_EQ(error_of([&] { (void)doc.at("captures").item(1).at("theta_i_deg").number(); }),
              "c.json: captures[1].theta_i_deg: must be a number, not \"30\"");
    EXPECT_EQ(error_of([&] { (void)doc.at("gamma").number(0.1, 2.0); }),
              "c.json: gamma: 2.2 must be in [0.1, 2]");
    EXPECT_EQ(error_of([&] { (void)doc.at("gamma").number(0.1, 2.0, " µm"); }),
              "c.json: gamma: 2.2 must be in [0.1, 2] µm");
    EXPECT_EQ(error_of([&] { (void)doc.at("captures").item(1).at("n").integer(0, 9); }),
              "c.json: captures[1].n: 2.5 must be a whole number in [0, 9]");
    EXPECT_EQ(error_of([&] { (void)doc.at("big").integer(0, 9); }),
              "c.json: big: 18446744073709551615 must be a whole number in [0, 9]");
    EXPECT_EQ(error_of([&] { (void)doc.at("count").integer(4, 9); }),
              "c.json: count: 3 must be a whole number in [4, 9]");
    EXPECT_EQ(error_of([&] { (void)doc.at("count").positive(); }), "no error");
    EXPECT_EQ(error_of([&] { (void)doc.at("flag").string(); }),
              "c.json: flag: must be a string, not true");
    EXPECT_EQ(error_of([&] { (void)doc.at("gamma").boolean(); }),
              "c.json: gamma: must be true or false, not 2.2");
    EXPECT_EQ(error_of([&] { (void)doc.at("pair").numbers(3); }),
              "c.json: pair: must be an array of 3 numbers, not [1,2]");
}

TEST(JsonReader, MissingUnknownAndOptionalKeys) {
    const JsonNode doc(kDoc, "c.json");
    EXPECT_EQ(error_of([&] { (void)doc.at("captures").item(0).at("view"); }),
              "c.json: captures[0]: missing key 'view'");
    EXPECT_EQ(error_of([&] { (void)doc.at("absent"); }), "c.json: missing key 'absent'");
    EXPECT_EQ(error_of([&] { doc.at("captures").item(0).only({"theta_i_deg"}); }),
              "c.json: captures[0].image: unknown key; valid keys: theta_i_deg");
    EXPECT_EQ(error_of([&] { doc.at("gamma").only({"a"}); }),
              "c.json: gamma: must be an object, not 2.2");
    EXPECT_FALSE(doc.find("none"));
    EXPECT_FALSE(doc.find("absent"));
    EXPECT_TRUE(doc.has("none"));
    EXPECT_FALSE(doc.given("none"));
    ASSERT_TRUE(doc.find("gamma"));
    EXPECT_EQ(doc.find("gamma")->path(), "gamma");
}

TEST(JsonReader, ArgumentsThrowInvalidArgumentFilesDataError) {
    const JsonNode options(kDoc, "fit options", JsonSource::Arguments);
    EXPECT_EQ(error_of<InvalidArgument>([&] { (void)options.at("flag").number(); }),
              "fit options: flag: must be a number, not true");
    const JsonNode file(kDoc, "c.json");
    EXPECT_THROW((void)file.at("flag").number(), DataError);
    // A library check's InvalidArgument and a name parser's are reported at the node.
    EXPECT_EQ(error_of([&] {
                  file.at("gamma").checked([] { throw InvalidArgument("gamma is too large"); });
              }),
              "c.json: gamma: gamma is too large");
}

TEST(JsonReader, TextAndFileErrorsNameThePlace) {
    EXPECT_EQ(error_of([] { (void)parse_json_text("{\n  \"a\": tru\n}\n", "t.json"); }),
              "t.json: line 2, column 11: not valid JSON: syntax error while parsing value - "
              "invalid literal");
    EXPECT_EQ(error_of([] { (void)parse_json_text(std::string("{\"a\"\0}", 6), "t.json"); }),
              "t.json: line 1, column 5: not a text file: NUL byte");
    EXPECT_NE(
        error_of([] { (void)parse_json_text("[1e999999]", "t.json"); }).find("not valid JSON"),
        std::string::npos);
    EXPECT_EQ(parse_json_text("\xEF\xBB\xBF{\"a\": 1}\r\n", "t.json")["a"], 1);
    const auto dir = std::filesystem::temp_directory_path() /
                     ("roughscope_json_reader_" +
                      std::to_string(::testing::UnitTest::GetInstance()->random_seed()));
    std::filesystem::create_directories(dir);
    EXPECT_EQ(error_of([&] { (void)read_json_file(dir / "absent.json"); }),
              (dir / "absent.json").string() + ": does not exist");
    EXPECT_EQ(error_of([&] { (void)read_json_file(dir, "a capture file"); }),
              dir.string() + ": is a directory, not a capture file");
    std::ofstream(dir / "ok.json") << R"({"a": [1, 2]})";
    EXPECT_EQ(read_json_file(dir / "ok.json")["a"][1], 2);
    std::filesystem::remove_all(dir);
}

}  // namespace
}  // namespace roughscope::io
