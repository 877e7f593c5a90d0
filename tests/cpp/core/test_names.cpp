// The enum-name scheme (roughscope/core/names.hpp) and every enum converted to it.
#include <array>
#include <string>

#include <gtest/gtest.h>

#include "roughscope/brdf/comparison.hpp"
#include "roughscope/brdf/curet.hpp"
#include "roughscope/core/names.hpp"
#include "roughscope/fit/fit.hpp"
#include "roughscope/scattering/beckmann.hpp"
#include "roughscope/scattering/factors.hpp"
#include "roughscope/scattering/validity.hpp"

using namespace roughscope;

namespace {
enum class Colour { Red, DarkBlue };
constexpr std::array<NameEntry<Colour>, 3> kColours{{
    {"red", Colour::Red},
    {"dark_blue", Colour::DarkBlue},
    {"navy", Colour::DarkBlue},
}};
}  // namespace

TEST(Names, NormalizeLowersTrimsAndUnifiesSeparators) {
    EXPECT_EQ(normalize_name("  Very-Rough "), "very_rough");
    EXPECT_EQ(normalize_name("SOFT_L-ONE"), "soft_l_one");
    EXPECT_EQ(normalize_name(""), "");
    EXPECT_TRUE(name_matches("dark_blue", "Dark-Blue"));
    EXPECT_FALSE(name_matches("dark_blue", "darkblue"));
}

TEST(Names, TableParsesCanonicalNamesAndAliases) {
    EXPECT_EQ(parse_name(kColours, "colour", "RED"), Colour::Red);
    EXPECT_EQ(parse_name(kColours, "colour", "dark-blue"), Colour::DarkBlue);
    EXPECT_EQ(parse_name(kColours, "colour", "Navy"), Colour::DarkBlue);
    EXPECT_EQ(name_of(kColours, Colour::DarkBlue), "dark_blue");  // the first entry
    EXPECT_EQ(canonical_names(kColours), (std::vector<std::string>{"red", "dark_blue"}));
}

TEST(Names, UnknownNameListsTheValidOnes) {
    try {
        parse_name(kColours, "colour", "green");
        FAIL() << "no exception";
    } catch (const InvalidArgument& e) {
        EXPECT_STREQ(e.what(),
                     "colour 'green' is not recognised; valid values: red, dark_blue, navy");
    }
}

// Every enum of the library: to_string round-trips through its parser in any case/separator.
TEST(Names, EveryEnumRoundTripsCaseInsensitively) {
    auto upper_dash = [](std::string_view s) {
        std::string o(s);
        for (char& c : o) c = c == '_' ? '-' : static_cast<char>(std::toupper(c));
        return o;
    };
    for (auto f : {GeometricFactor::Beckmann, GeometricFactor::VernoldHarvey,
                   GeometricFactor::Ogilvy, GeometricFactor::Kirchhoff})
        EXPECT_EQ(parse_geometric_factor(upper_dash(to_string(f))), f);
    for (auto r : {Radiometry::Radiance, Radiometry::Intensity})
        EXPECT_EQ(parse_radiometry(upper_dash(to_string(r))), r);
    for (auto c : {Correlation::Gaussian, Correlation::Exponential})
        EXPECT_EQ(parse_correlation(upper_dash(to_string(c))), c);
    for (auto r : {Regime::Auto, Regime::Series, Regime::SlightlyRough, Regime::VeryRough,
                   Regime::VeryRoughSeriesLimit})
        EXPECT_EQ(parse_regime(upper_dash(to_string(r))), r);
    for (auto c : {RoughnessClass::SlightlyRough, RoughnessClass::ModeratelyRough,
                   RoughnessClass::VeryRough})
        EXPECT_EQ(parse_roughness_class(upper_dash(to_string(c))), c);
    for (auto m : {FitModel::VeryRough, FitModel::SlightlyRough})
        EXPECT_EQ(parse_fit_model(upper_dash(to_string(m))), m);
    for (auto r : {ResidualType::Relative, ResidualType::Absolute, ResidualType::Log})
        EXPECT_EQ(parse_residual_type(upper_dash(to_string(r))), r);
    for (auto l : {LossType::None, LossType::Huber, LossType::Cauchy, LossType::SoftLOne})
        EXPECT_EQ(parse_loss_type(upper_dash(to_string(l))), l);
    for (auto c : {CuretChannel::Mean, CuretChannel::Red, CuretChannel::Green, CuretChannel::Blue})
        EXPECT_EQ(parse_curet_channel(upper_dash(to_string(c))), c);
    EXPECT_EQ(parse_curet_channel("G"), CuretChannel::Green);
    for (auto m : {ComparisonModel::OrenNayar, ComparisonModel::VhExponentialFit})
        EXPECT_EQ(parse_comparison_model(upper_dash(to_string(m))), m);
    EXPECT_EQ(to_string(SolverStatus::NoConvergence), "no_convergence");
    EXPECT_EQ(to_string(SolverStatus::AtBound), "at_bound");
    EXPECT_EQ(to_string(SolverStatus::NotIdentifiable), "not_identifiable");
}

TEST(Names, EveryParserRejectsUnknownNames) {
    EXPECT_THROW(parse_geometric_factor("phong"), InvalidArgument);
    EXPECT_THROW(parse_radiometry("power"), InvalidArgument);
    EXPECT_THROW(parse_correlation("lorentzian"), InvalidArgument);
    EXPECT_THROW(parse_regime("rough"), InvalidArgument);
    EXPECT_THROW(parse_roughness_class("smooth"), InvalidArgument);
    EXPECT_THROW(parse_fit_model("both"), InvalidArgument);
    EXPECT_THROW(parse_residual_type("squared"), InvalidArgument);
    EXPECT_THROW(parse_loss_type("tukey"), InvalidArgument);
    EXPECT_THROW(parse_curet_channel("alpha"), InvalidArgument);
    EXPECT_THROW(parse_comparison_model("phong"), InvalidArgument);
}
