// The CUReT database and the paper's §5.3 comparison (Tables 3 and 4).
// Real data: ../shared/data/curet and printed values: ../shared/reference/paper-tables.json, found
// by io/data_locator.hpp (tests skip, saying so, when absent; fail under
// ROUGHSCOPE_REQUIRE_SHARED_DATA=1).
#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <functional>
#include <map>
#include <sstream>
#include <string>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "../io/shared_data.hpp"
#include "roughscope/brdf/comparison.hpp"
#include "roughscope/brdf/curet.hpp"
#include "roughscope/core/errors.hpp"
#include "roughscope/scattering/beckmann.hpp"
#include "roughscope/scattering/reflectance_models.hpp"

using namespace roughscope;
namespace fs = std::filesystem;

namespace {

// Located by io/data_locator.hpp (empty paths when absent).
fs::path curet_dir() { return roughscope::testing::curet_dir().value_or(fs::path()); }
fs::path tables_path() { return roughscope::testing::paper_tables().value_or(fs::path()); }

#define REQUIRE_CURET() ROUGHSCOPE_NEED_SHARED(roughscope::testing::curet_dir(), io::kCuretRelative)
#define REQUIRE_TABLES() \
    ROUGHSCOPE_NEED_SHARED(roughscope::testing::paper_tables(), io::kPaperTablesRelative)

const CuretDatabase& database() {
    static const CuretDatabase db = load_curet(curet_dir());
    return db;
}

nlohmann::json paper_tables() {
    std::ifstream in(tables_path());
    return nlohmann::json::parse(in);
}

// Rounds to `digits` significant digits.
double significant(double x, int digits) {
    const double scale = std::pow(10.0, digits - 1 - std::floor(std::log10(std::abs(x))));
    return std::round(x * scale) / scale;
}

// Synthetic CUReT files in a temporary directory (independent of the real data).
struct SyntheticCuret {
    fs::path dir;
    explicit SyntheticCuret(const std::string& tag) {
        dir = fs::temp_directory_path() /
              ("roughscope_curet_" + tag + "_" +
               std::to_string(::testing::UnitTest::GetInstance()->random_seed()));
        fs::create_directories(dir);
        std::ofstream table(dir / "table.txt");
        for (int j = 1; j <= kCuretMeasurementCount; ++j) {
            double tv = 0.01 * (j % 80), pv = 0.03 * j, ti = 0.012 * (j % 100), pi = -0.02 * j;
            if (j == kCuretTwoPointMeasurement1) tv = 0.0, pv = 0.0, ti = 0.785398, pi = 0.0;
            if (j == kCuretTwoPointMeasurement2) tv = 1e-6, pv = 0.0, ti = 1.178097, pi = 0.0;
            table << j << " " << tv << " " << pv << " " << ti << " " << pi << "\n";
        }
    }
    void write_samples(const std::string& file, const std::vector<int>& samples, double value) {
        std::ofstream f(dir / file);
        for (int s : samples) {
            f << s;
            for (int j = 1; j <= kCuretMeasurementCount; ++j) f << " " << value * (1 + 0.001 * j);
            f << "\n";
        }
    }
    ~SyntheticCuret() {
        std::error_code ec;
        fs::remove_all(dir, ec);
    }
};

}  // namespace

// ---------------------------------------------------------------------------------------------
// Loading

TEST(Curet, LoadsTheDatabaseAsTheReadmeDescribes) {
    REQUIRE_CURET();
    const CuretDatabase& db = database();
    ASSERT_EQ(db.samples.size(), static_cast<std::size_t>(kCuretSampleCount));
    ASSERT_EQ(db.angles.size(), static_cast<std::size_t>(kCuretMeasurementCount));
    EXPECT_EQ(db.samples.front(), 1);
    EXPECT_EQ(db.samples.back(), 61);
    // Measurement 81: θv = 0, θi = 45°, φi = 0; 112: θv ≈ 0, θi = 67.5° (README).
    const CuretAngles& a81 = db.angles[80];
    const CuretAngles& a112 = db.angles[111];
    EXPECT_EQ(a81.measurement, 81);
    EXPECT_NEAR(a81.theta_v_rad, 0.0, 1e-6);
    EXPECT_NEAR(rad_to_deg(a81.theta_i_rad), 45.0, 1e-4);
    EXPECT_NEAR(a112.theta_v_rad, 0.0, 1e-5);
    EXPECT_NEAR(rad_to_deg(a112.theta_i_rad), 67.5, 1e-4);
    // 43 of the 12,505 values are ≤ 0, and they are loaded as they are.
    int nonpositive = 0;
    for (const auto& row : db.brdf)
        for (double f : row) nonpositive += f <= 0.0;
    EXPECT_EQ(nonpositive, 43);
    EXPECT_TRUE(db.overflow.empty());  // no overflow files in the shared copy
}

TEST(Curet, SampleTableUsesThePaperFrame) {
    REQUIRE_CURET();
    const BrdfTable t = database().sample_table(25);
    ASSERT_EQ(t.size(), static_cast<std::size_t>(kCuretMeasurementCount));
    for (const BrdfMeasurement& m : t.measurements) {
        // θs = θv and cos(φs) = cos(φv − φi + π) = −cos(φv − φi).
        EXPECT_DOUBLE_EQ(m.geometry.theta_s_rad, m.theta_v_rad);
        EXPECT_NEAR(std::cos(m.geometry.phi_s_rad), -std::cos(m.phi_v_rad - m.phi_i_rad), 1e-12);
    }
}

TEST(Curet, UnknownSampleAndChannelAreErrors) {
    REQUIRE_CURET();
    EXPECT_THROW(database().sample_table(62), InvalidArgument);
    EXPECT_THROW(compare_curet_sample(database(), 0), InvalidArgument);
    try {
        load_curet(curet_dir(), CuretChannel::Red);  // rbrdf.dat is not in the shared copy
        FAIL() << "expected DataError";
    } catch (const DataError& e) {
        EXPECT_NE(std::string(e.what()).find("rbrdf.dat"), std::string::npos) << e.what();
    }
    EXPECT_THROW(parse_curet_channel("purple"), InvalidArgument);
    EXPECT_EQ(parse_curet_channel("g"), CuretChannel::Green);
}

TEST(CuretFiles, SyntheticFilesLoadWithOverflowFractions) {
    SyntheticCuret s("ok");
    s.write_samples("abrdf.dat", {3, 9}, 0.05);
    s.write_samples("rover.dat", {9, 3}, 0.1);
    s.write_samples("bover.dat", {3, 9}, 0.2);
    const CuretDatabase db = load_curet(s.dir);
    EXPECT_EQ(db.samples, (std::vector<int>{3, 9}));
    ASSERT_EQ(db.overflow.size(), 2u);
    // The mean channel takes the largest fraction over the channel files present.
    EXPECT_NEAR(db.overflow[0][0], 0.2 * 1.001, 1e-12);
    EXPECT_EQ(db.overflow_files, (std::vector<std::string>{"rover.dat", "bover.dat"}));
    EXPECT_NEAR(db.brdf[1][204], 0.05 * 1.205, 1e-12);
    const BrdfTable t = db.sample_table(9);
    ASSERT_TRUE(t.measurements[0].overflow_fraction.has_value());
}

TEST(CuretFiles, MalformedFilesNameTheFileAndLine) {
    auto error_of = [](const fs::path& dir) {
        try {
            load_curet(dir);
        } catch (const DataError& e) {
            return std::string(e.what());
        }
        return std::string("no error");
    };
    {
        SyntheticCuret s("missing");
        EXPECT_NE(error_of(s.dir).find("abrdf.dat"), std::string::npos);
    }
    {
        SyntheticCuret s("nan");
        s.write_samples("abrdf.dat", {1}, 0.05);
        std::ofstream(s.dir / "abrdf.dat", std::ios::app) << "2 nan\n";
        const std::string e = error_of(s.dir);
        EXPECT_NE(e.find("abrdf.dat:2: expected 206 fields"), std::string::npos) << e;
    }
    {
        SyntheticCuret s("dup");
        s.write_samples("abrdf.dat", {4, 4}, 0.05);
        EXPECT_NE(error_of(s.dir).find("abrdf.dat:2: sample 4 appears twice"), std::string::npos);
    }
    {
        SyntheticCuret s("badnum");
        std::ofstream f(s.dir / "abrdf.dat");
        f << "1";
        for (int j = 1; j <= kCuretMeasurementCount; ++j) f << (j == 7 ? " 0.1x" : " 0.1");
        f << "\n";
        f.close();
        EXPECT_NE(error_of(s.dir).find("abrdf.dat:1: field 8 (BRDF value): '0.1x'"),
                  std::string::npos)
            << error_of(s.dir);
    }
    {
        SyntheticCuret s("angles");
        s.write_samples("abrdf.dat", {1}, 0.05);
        std::ofstream(s.dir / "table.txt") << "1 0.1 0 2.0 0\n";
        EXPECT_NE(error_of(s.dir).find("table.txt:1: theta_i"), std::string::npos)
            << error_of(s.dir);
    }
    {
        SyntheticCuret s("overflow");
        s.write_samples("abrdf.dat", {1}, 0.05);
        s.write_samples("gover.dat", {1}, 2.0);  // fractions > 1
        EXPECT_NE(error_of(s.dir).find("gover.dat:1: measurement 1: overflow fraction"),
                  std::string::npos)
            << error_of(s.dir);
    }
}

TEST(CuretFiles, FindDirectoryExplainsWhatIsMissing) {
    try {
        find_curet_directory(fs::path("/nonexistent/curet"));
        FAIL() << "expected DataError";
    } catch (const DataError& e) {
        const std::string m = e.what();
        EXPECT_NE(m.find("table.txt"), std::string::npos) << m;
        EXPECT_NE(m.find("abrdf.dat"), std::string::npos) << m;
        EXPECT_NE(m.find("CUReT"), std::string::npos) << m;
    }
    SyntheticCuret s("find");
    s.write_samples("abrdf.dat", {1}, 0.05);
    EXPECT_EQ(find_curet_directory(s.dir), s.dir);
}

// ---------------------------------------------------------------------------------------------
// Table 3

TEST(CuretPaper, Table3EstimatesMatchThePrintedValues) {
    REQUIRE_CURET();
    REQUIRE_TABLES();
    const nlohmann::json t3 = paper_tables()["table3_curet_parameters"];
    for (const auto& row : t3["rows"]) {
        const int sample = row["sample"];
        const Comparison c = compare_curet_sample(database(), sample);
        ASSERT_TRUE(c.two_point.available) << c.two_point.reason;
        // 5 significant digits with the angle table's own θi.
        EXPECT_EQ(significant(*c.two_point.E1_over_E2, 5),
                  significant(row["E1_over_E2"].get<double>(), 5))
            << "sample " << sample;
        // σ/T to the 4 printed decimals.
        EXPECT_NEAR(*c.two_point.sigma_over_T_gaussian, row["sigma_over_T_G"].get<double>(), 0.5e-4)
            << "sample " << sample;
        EXPECT_NEAR(*c.two_point.sigma_over_T_exponential, row["sigma_over_T_E"].get<double>(),
                    0.5e-4)
            << "sample " << sample;
        // With the nominal angles θ1 = 45°, θ2 = 67.5° all 7 printed digits come back: the
        // residual difference above is the angle table's last digit for measurement 112.
        ComparisonOptions nominal;
        nominal.theta1_rad = deg_to_rad(t3["conditions"]["theta1_deg"].get<double>());
        nominal.theta2_rad = deg_to_rad(t3["conditions"]["theta2_deg"].get<double>());
        nominal.fits = false;
        const Comparison n = compare_curet_sample(database(), sample, nominal);
        EXPECT_NEAR(*n.two_point.E1_over_E2, row["E1_over_E2"].get<double>(), 0.5e-6)
            << "sample " << sample;
        // The paper's Oren–Nayar parameters are the ones used.
        const ModelResult& on = c.result(ComparisonModel::OrenNayar);
        EXPECT_DOUBLE_EQ(*on.parameter("sigma_rad"), row["sigma_ON_rad"].get<double>());
        EXPECT_DOUBLE_EQ(*on.parameter("albedo"), row["rho_ON"].get<double>());
    }
}

// ---------------------------------------------------------------------------------------------
// Table 4

TEST(CuretPaper, Table4VeryRoughColumnsWithinOneTenthPercent) {
    REQUIRE_CURET();
    REQUIRE_TABLES();
    const nlohmann::json t4 = paper_tables()["table4_curet_errors"];
    const ComparisonModel columns[] = {ComparisonModel::BkGaussian, ComparisonModel::BkExponential,
                                       ComparisonModel::VhGaussian, ComparisonModel::VhExponential};
    for (const auto& row : t4["rows"]) {
        const int sample = row["sample"];
        ComparisonOptions o;
        o.fits = false;
        const Comparison c = compare_curet_sample(database(), sample, o);
        for (int k = 0; k < 4; ++k) {
            const double printed = row["values"][2 + k].get<double>();
            const double got = c.result(columns[k]).errors.paper_sse;
            EXPECT_NEAR(got / printed - 1.0, 0.0, 1e-3)
                << "sample " << sample << " " << to_string(columns[k]) << ": " << got
                << " vs printed " << printed;
        }
    }
}

TEST(CuretPaper, Table4OrenNayarForSamples25And34WithinHalfAPercent) {
    REQUIRE_CURET();
    REQUIRE_TABLES();
    const nlohmann::json t4 = paper_tables()["table4_curet_errors"];
    for (const auto& row : t4["rows"]) {
        const int sample = row["sample"];
        if (sample == 41) continue;  // not reproducible; see the next test and docs/curet.md
        ComparisonOptions o;
        o.fits = false;
        const double got = compare_curet_sample(database(), sample, o)
                               .result(ComparisonModel::OrenNayar)
                               .errors.paper_sse;
        const double printed = row["values"][0].get<double>();
        EXPECT_NEAR(got / printed - 1.0, 0.0, 5e-3) << "sample " << sample << ": " << got;
    }
}

TEST(CuretPaper, Table4RankingStatedInThePaperHolds) {
    // §5.3: V–H below B–K ("an order of magnitude lower"), B–K(G) below B–K(E), O–N above both
    // B–K variants, LFTG below O–N and above V–H, for the three samples. This also holds for the
    // values that are not reproduced exactly (O–N for 41, LFTG).
    REQUIRE_CURET();
    for (int sample : {25, 34, 41}) {
        ComparisonOptions o;
        o.fits = false;
        const Comparison c = compare_curet_sample(database(), sample, o);
        auto e = [&](ComparisonModel m) { return c.result(m).errors.paper_sse; };
        EXPECT_LT(5.0 * e(ComparisonModel::VhGaussian), e(ComparisonModel::BkGaussian));
        EXPECT_LT(5.0 * e(ComparisonModel::VhExponential), e(ComparisonModel::BkExponential));
        EXPECT_LT(e(ComparisonModel::BkGaussian), e(ComparisonModel::BkExponential));
        EXPECT_GT(e(ComparisonModel::OrenNayar), e(ComparisonModel::BkExponential));
        EXPECT_LT(e(ComparisonModel::Lafortune), e(ComparisonModel::OrenNayar));
        EXPECT_GT(e(ComparisonModel::Lafortune), e(ComparisonModel::VhGaussian));
        EXPECT_GT(e(ComparisonModel::Lafortune), e(ComparisonModel::VhExponential));
    }
}

TEST(CuretPaper, PredictionsAreTheCoreModels) {
    // The comparison evaluates the models through precomputed terms; they must equal the core
    // functions at every geometry (Oren–Nayar through oren_nayar_radiance, LFTG through
    // lafortune_diffuse_brightness, B–K/V–H through very_rough_brightness).
    REQUIRE_CURET();
    const Comparison c = compare_curet_sample(database(), 25);
    const ModelResult& on = c.result(ComparisonModel::OrenNayar);
    const ModelResult& laf = c.result(ComparisonModel::LafortuneFit);
    const ModelResult& bk = c.result(ComparisonModel::BkGaussian);
    const ModelResult& vh = c.result(ComparisonModel::VhExponentialFit);
    const OrenNayarParams on_params{*on.parameter("sigma_rad"), *on.parameter("albedo")};
    for (std::size_t j = 0; j < c.geometry.size(); ++j) {
        const Geometry& g = c.geometry[j];
        EXPECT_DOUBLE_EQ(on.prediction[j], oren_nayar_radiance(g, on_params));
        EXPECT_NEAR(laf.prediction[j], lafortune_diffuse_brightness(g, *laf.parameter("n")),
                    1e-13 * laf.prediction[j] + 1e-300);
        EXPECT_NEAR(bk.prediction[j],
                    very_rough_brightness(g, *bk.parameter("sigma_over_T"), Correlation::Gaussian,
                                          GeometricFactor::Beckmann),
                    1e-12 * bk.prediction[j]);
        EXPECT_NEAR(
            vh.prediction[j],
            very_rough_brightness(g, *vh.parameter("sigma_over_T"), Correlation::Exponential),
            1e-12 * vh.prediction[j]);
        EXPECT_NEAR(c.brightness[j],
                    database().brdf[24][static_cast<std::size_t>(c.measurement[j] - 1)] *
                        std::cos(g.theta_i_rad),
                    1e-15);
    }
}

TEST(CuretPaper, FitsNeverDoWorseThanTheTwoPointEstimate) {
    // The least-squares fit minimises the gain SSE over σ/T, so it cannot be above the two-point
    // value of the same family (which is inside its search interval).
    REQUIRE_CURET();
    for (int sample : {7, 25, 34, 41, 57}) {
        const Comparison c = compare_curet_sample(database(), sample);
        const std::pair<ComparisonModel, ComparisonModel> pairs[] = {
            {ComparisonModel::BkGaussian, ComparisonModel::BkGaussianFit},
            {ComparisonModel::BkExponential, ComparisonModel::BkExponentialFit},
            {ComparisonModel::VhGaussian, ComparisonModel::VhGaussianFit},
            {ComparisonModel::VhExponential, ComparisonModel::VhExponentialFit},
        };
        for (const auto& [paper, fit] : pairs)
            EXPECT_LE(c.result(fit).errors.gain_sse, c.result(paper).errors.gain_sse * (1 + 1e-9))
                << "sample " << sample << " " << to_string(fit);
        // The exhaustive search's n_d is a minimum of the Table-4 error on its grid.
        const double n = *c.result(ComparisonModel::Lafortune).parameter("n");
        EXPECT_GE(n, 0.1 - 1e-12);
        EXPECT_LE(n, 20.0 + 1e-12);
    }
}

// ---------------------------------------------------------------------------------------------
// The fits on the library's least-squares engine against the previous engine (grid + Brent with
// the gain eliminated, finite-difference covariance), whose values for six samples are typed in
// below: gain_sse agrees to 1e-9, the fitted parameter to 1e-5 (σ/T, n; 1e-4 for σ_ON), the
// standard error to 1e-4 (relative). Where σ_ON = 0 (Lambert), albedo and gain trade off exactly:
// the old engine reported no covariance, the new one says NotIdentifiable.

TEST(CuretFitEngine, TableFourFitsAgreeWithThePreviousEngine) {
    REQUIRE_CURET();
    struct Old {
        int sample;
        ComparisonModel model;
        double gain_sse;
        const char* parameter;
        double value;
        double standard_error;  // -1: none
    };
    const Old old[] = {
        {7, ComparisonModel::OrenNayarFit, 5.77215248485, "sigma_rad", 0.697095409992, 1.98148},
        {7, ComparisonModel::LafortuneFit, 6.50229713458, "n", 0.01, 0.0670658},
        {7, ComparisonModel::BkGaussianFit, 18.109661831, "sigma_over_T", 0.468795504013,
         0.0426574},
        {7, ComparisonModel::BkExponentialFit, 14.6166245337, "sigma_over_T", 0.543579586036,
         0.051324},
        {7, ComparisonModel::VhGaussianFit, 3.16368302148, "sigma_over_T", 4.6076966318, 0.702779},
        {7, ComparisonModel::VhExponentialFit, 3.15018433293, "sigma_over_T", 10.1213922223,
         1.62953},
        {15, ComparisonModel::OrenNayarFit, 7.99056682754, "sigma_rad", 0, -1},
        {15, ComparisonModel::LafortuneFit, 7.84515466749, "n", 0.133638631788, 0.0674979},
        {15, ComparisonModel::BkGaussianFit, 24.5169789139, "sigma_over_T", 0.227195007204,
         0.0324734},
        {15, ComparisonModel::BkExponentialFit, 24.5656172182, "sigma_over_T", 0.31020397419,
         0.0498608},
        {15, ComparisonModel::VhGaussianFit, 10.3173585506, "sigma_over_T", 0.41028263481,
         0.0321183},
        {15, ComparisonModel::VhExponentialFit, 9.76475609561, "sigma_over_T", 0.792561156953,
         0.0750624},
        {25, ComparisonModel::OrenNayarFit, 7.99000026821, "sigma_rad", 0, -1},
        {25, ComparisonModel::LafortuneFit, 8.02599638973, "n", 0.01, 0.0875827},
        {25, ComparisonModel::BkGaussianFit, 12.445859484, "sigma_over_T", 0.23348562516,
         0.0195269},
        {25, ComparisonModel::BkExponentialFit, 12.2521960516, "sigma_over_T", 0.319133205731,
         0.0291124},
        {25, ComparisonModel::VhGaussianFit, 1.88829396852, "sigma_over_T", 0.479192306653,
         0.0177187},
        {25, ComparisonModel::VhExponentialFit, 1.34894045044, "sigma_over_T", 0.920447826561,
         0.0350708},
        {30, ComparisonModel::OrenNayarFit, 0.299470270669, "sigma_rad", 0.528583459411, 0.123011},
        {30, ComparisonModel::LafortuneFit, 3.10373366679, "n", 0.01, 0.0200407},
        {30, ComparisonModel::BkGaussianFit, 77.5944191074, "sigma_over_T", 0.693707307958,
         0.0838121},
        {30, ComparisonModel::BkExponentialFit, 75.9107254928, "sigma_over_T", 0.607915510202,
         0.128309},
        {30, ComparisonModel::VhGaussianFit, 37.1349975657, "sigma_over_T", 1.94300141788,
         0.283093},
        {30, ComparisonModel::VhExponentialFit, 36.9773840305, "sigma_over_T", 4.12719174103,
         0.728017},
        {34, ComparisonModel::OrenNayarFit, 6.77838043035, "sigma_rad", 0, -1},
        {34, ComparisonModel::LafortuneFit, 6.79237746296, "n", 0.01, 0.116288},
        {34, ComparisonModel::BkGaussianFit, 7.40837324349, "sigma_over_T", 0.198270071607,
         0.0163995},
        {34, ComparisonModel::BkExponentialFit, 7.29047815463, "sigma_over_T", 0.282020536084,
         0.0250981},
        {34, ComparisonModel::VhGaussianFit, 1.17696487542, "sigma_over_T", 0.331044488841,
         0.0106409},
        {34, ComparisonModel::VhExponentialFit, 0.846420164185, "sigma_over_T", 0.64174925958,
         0.0223989},
        {41, ComparisonModel::OrenNayarFit, 7.56649663534, "sigma_rad", 0, -1},
        {41, ComparisonModel::LafortuneFit, 7.58371960924, "n", 0.01, 0.116329},
        {41, ComparisonModel::BkGaussianFit, 7.9304709505, "sigma_over_T", 0.195559648907,
         0.0154492},
        {41, ComparisonModel::BkExponentialFit, 7.92060367033, "sigma_over_T", 0.289932546983,
         0.0246323},
        {41, ComparisonModel::VhGaussianFit, 1.57182790089, "sigma_over_T", 0.304165958388,
         0.0105852},
        {41, ComparisonModel::VhExponentialFit, 1.23541330778, "sigma_over_T", 0.606475899771,
         0.0242178},
    };
    int checked = 0;
    for (const Old& o : old) {
        const Comparison c = compare_curet_sample(database(), o.sample);
        const ModelResult& r = c.result(o.model);
        const std::string where = "sample " + std::to_string(o.sample) + " " +
                                  std::string(to_string(o.model)) + ": " + r.fit_message;
        ASSERT_TRUE(r.available) << where;
        ASSERT_TRUE(r.fit_status.has_value()) << where;
        EXPECT_NEAR(r.errors.gain_sse, o.gain_sse, 1e-9 * o.gain_sse) << where;
        const std::optional<double> v = r.parameter(o.parameter);
        ASSERT_TRUE(v.has_value()) << where;
        const double tol = std::string(o.parameter) == "sigma_rad" ? 1e-4 : 1e-5;
        EXPECT_NEAR(*v, o.value, tol * std::max(o.value, 1e-3)) << where;
        const ModelParameter& p = r.parameters.at(0);
        if (o.standard_error > 0.0 && p.standard_error) {
            EXPECT_NEAR(*p.standard_error, o.standard_error, 1e-4 * o.standard_error) << where;
        }
        if (o.model == ComparisonModel::OrenNayarFit && o.value == 0.0) {
            EXPECT_EQ(*r.fit_status, SolverStatus::NotIdentifiable) << where;
            EXPECT_FALSE(p.standard_error.has_value()) << where;
        }
        if (o.model != ComparisonModel::OrenNayarFit && o.model != ComparisonModel::LafortuneFit) {
            EXPECT_EQ(*r.fit_status, SolverStatus::Converged) << where;
        }
        EXPECT_NE(*r.fit_status, SolverStatus::Failed) << where;
        ++checked;
    }
    EXPECT_EQ(checked, 36);
}

// ---------------------------------------------------------------------------------------------
// The whole database, including sample 61

TEST(CuretAll, EverySampleIsProcessedAndSample61ExplainsItsMissingEstimate) {
    REQUIRE_CURET();
    const std::vector<Comparison> all = compare_curet_all(database(), {}, 2);
    ASSERT_EQ(all.size(), 61u);
    int with_estimate = 0, nonpositive = 0;
    for (const Comparison& c : all) {
        with_estimate += c.two_point.available;
        for (const DataIssue& d : c.data_issues) nonpositive += d.issue == "non_positive";
        EXPECT_EQ(c.measurement.size(), 205u) << "sample " << c.sample;  // nothing dropped
        EXPECT_TRUE(c.winner.has_value()) << "sample " << c.sample;
    }
    EXPECT_EQ(with_estimate, 60);
    EXPECT_EQ(nonpositive, 43);
    const Comparison& c61 = all.back();
    ASSERT_EQ(c61.sample, 61);
    EXPECT_FALSE(c61.two_point.available);
    EXPECT_NE(c61.two_point.reason.find("measurement 81 has f = -0.001 <= 0"), std::string::npos)
        << c61.two_point.reason;
    EXPECT_NE(c61.two_point.reason.find("measurement 112"), std::string::npos);
    int excluded = 0;
    for (const DataIssue& d : c61.data_issues)
        if (!d.excluded_from.empty()) {
            ++excluded;
            EXPECT_TRUE(d.measurement == 81 || d.measurement == 112);
            EXPECT_EQ(d.excluded_from.front(), "two_point_estimate");
        }
    EXPECT_EQ(excluded, 2);
    EXPECT_FALSE(c61.result(ComparisonModel::VhGaussian).available);
    EXPECT_TRUE(c61.result(ComparisonModel::VhGaussianFit).available);
    EXPECT_TRUE(c61.result(ComparisonModel::Lafortune).available);
    // Threads do not change results.
    const std::vector<Comparison> one = compare_curet_all(database(), {}, 1);
    for (std::size_t k = 0; k < all.size(); ++k)
        EXPECT_EQ(one[k].result(ComparisonModel::VhExponentialFit).errors.gain_sse,
                  all[k].result(ComparisonModel::VhExponentialFit).errors.gain_sse);
    EXPECT_THROW(compare_curet_all(database(), {}, -1), InvalidArgument);
}

// ---------------------------------------------------------------------------------------------
// The reading policy of docs/input-files.md on the CUReT files and the BRDF table CSV

namespace {

std::string load_error(const fs::path& dir) {
    try {
        load_curet(dir);
    } catch (const DataError& e) {
        return e.what();
    }
    return "no error";
}

// table.txt of `s` rewritten line by line by `edit`.
void rewrite_table(const SyntheticCuret& s,
                   const std::function<std::string(const std::string&)>& edit,
                   const std::string& prefix = "") {
    std::ifstream in(s.dir / "table.txt");
    std::string text = prefix, line;
    while (std::getline(in, line)) text += edit(line);
    in.close();
    std::ofstream(s.dir / "table.txt", std::ios::binary) << text;
}

}  // namespace

TEST(CuretFiles, BomCrlfAndSurroundingSpacesAreAccepted) {
    SyntheticCuret s("policy");
    s.write_samples("abrdf.dat", {3}, 0.05);
    rewrite_table(
        s, [](const std::string& line) { return " \t" + line + " \t\r\n"; }, "\xEF\xBB\xBF");
    const CuretDatabase db = load_curet(s.dir);
    EXPECT_EQ(db.angles.size(), static_cast<std::size_t>(kCuretMeasurementCount));
    EXPECT_EQ(db.samples, std::vector<int>{3});
}

TEST(CuretFiles, HexNanBinaryAndNonDecimalIntegersAreRefusedWithFileAndLine) {
    {
        SyntheticCuret s("hex");
        s.write_samples("abrdf.dat", {3}, 0.05);
        rewrite_table(s, [](const std::string& line) {
            return (line.starts_with("7 ") ? "0x" : "") + line + "\n";
        });
        const std::string e = load_error(s.dir);
        EXPECT_NE(e.find("table.txt:7: field 1 (measurement): '0x7' is not an integer"),
                  std::string::npos)
            << e;
    }
    {
        SyntheticCuret s("decimal_sample");
        s.write_samples("abrdf.dat", {3}, 0.05);
        std::string text;
        {
            std::ifstream in(s.dir / "abrdf.dat");
            std::getline(in, text);
        }
        std::ofstream(s.dir / "abrdf.dat") << "3.0" << text.substr(1) << "\n";
        const std::string e = load_error(s.dir);
        EXPECT_NE(e.find("abrdf.dat:1: field 1 (sample number): '3.0' is not an integer"),
                  std::string::npos)
            << e;
    }
    {
        SyntheticCuret s("binary");
        s.write_samples("abrdf.dat", {3}, 0.05);
        std::ofstream(s.dir / "table.txt", std::ios::binary) << "\x7f"
                                                                "ELF\x02\x01\x01"
                                                             << '\0' << "\x1b[2J";
        const std::string e = load_error(s.dir);
        EXPECT_NE(e.find("table.txt:1: not a text file: NUL byte at column 8"), std::string::npos)
            << e;
        EXPECT_EQ(e.find('\x1b'), std::string::npos);
    }
    {
        SyntheticCuret s("empty");
        s.write_samples("abrdf.dat", {3}, 0.05);
        std::ofstream(s.dir / "table.txt", std::ios::trunc).close();
        const std::string e = load_error(s.dir);
        EXPECT_NE(e.find("table.txt: 0 measurement rows"), std::string::npos) << e;
    }
    {
        SyntheticCuret s("dir");
        s.write_samples("abrdf.dat", {3}, 0.05);
        fs::remove(s.dir / "table.txt");
        fs::create_directory(s.dir / "table.txt");
        // find_curet_directory wants a regular file; load_curet says what is wrong.
        const std::string e = load_error(s.dir);
        EXPECT_NE(e.find("table.txt: is a directory, not a file"), std::string::npos) << e;
    }
}

TEST(CuretFiles, DataPathThatIsAFileIsNotADirectory) {
    SyntheticCuret s("notdir");
    s.write_samples("abrdf.dat", {3}, 0.05);
    try {
        find_curet_directory(s.dir / "abrdf.dat");
        FAIL() << "expected DataError";
    } catch (const DataError& e) {
        const std::string m = e.what();
        EXPECT_NE(m.find("abrdf.dat is not a directory"), std::string::npos) << m;
        EXPECT_EQ(m.find("does not exist"), std::string::npos) << m;
    }
}

TEST(BrdfCsvPolicy, SameVariantsAsEveryReader) {
    const std::string header = "theta_i,phi_i,theta_s,phi_s,value\n";
    const std::string row = "30,180,20,0,0.5\n";
    // Accepted: BOM, CRLF, spaces and tabs around fields.
    EXPECT_EQ(parse_brdf_csv("\xEF\xBB\xBF" + header + row, "t.csv").size(), 1u);
    EXPECT_EQ(
        parse_brdf_csv("theta_i,phi_i,theta_s,phi_s,value\r\n30,180,20,0,0.5\r\n", "t.csv").size(),
        1u);
    EXPECT_EQ(parse_brdf_csv(
                  " theta_i ,\tphi_i, theta_s,phi_s ,value \t\n 30 ,180\t, 20,0 ,0.5 \t\n", "t.csv")
                  .size(),
              1u);
    // Refused, naming the file and the line: hex, NaN, NUL bytes, a huge bad cell (cut).
    auto error_of = [](const std::string& text) {
        try {
            parse_brdf_csv(text, "t.csv");
        } catch (const DataError& e) {
            return std::string(e.what());
        }
        return std::string("no error");
    };
    EXPECT_NE(error_of(header + "0x1e,180,20,0,0.5\n").find("t.csv:2: column theta_i: '0x1e'"),
              std::string::npos);
    EXPECT_NE(error_of(header + "30,180,20,0,nan\n").find("t.csv:2: column value: 'nan'"),
              std::string::npos);
    EXPECT_NE(error_of(header + std::string("30,180,20,0,0.5\0\n", 17))
                  .find("t.csv:2: not a text file: NUL byte at column 16"),
              std::string::npos)
        << error_of(header + std::string("30,180,20,0,0.5\0\n", 17));
    const std::string huge =
        error_of(header + "30,180,20,0," + std::string(10'000'000, '5') + "x\n");
    EXPECT_LT(huge.size(), 200u);
    EXPECT_NE(huge.find("t.csv:2: column value: '555"), std::string::npos) << huge;
    EXPECT_NE(huge.find("(10000001 bytes in all)"), std::string::npos) << huge;
    const std::string ansi = error_of("theta_i,\x1b[31mphi_i,theta_s,phi_s,value\n" + row);
    EXPECT_EQ(ansi.find('\x1b'), std::string::npos) << ansi;
    EXPECT_NE(ansi.find("\\x1b[31mphi_i"), std::string::npos) << ansi;
}

TEST(BrdfCsvPolicy, MeasurementNumbersAreDecimalDigitsOnly) {
    const std::string header = "theta_i,phi_i,theta_s,phi_s,value,measurement\n";
    EXPECT_EQ(parse_brdf_csv(header + "30,180,20,0,0.5, 7 \n", "t.csv").measurements[0].index, 7);
    for (const char* bad : {"7.0", "0x7", "7e0"}) {
        try {
            parse_brdf_csv(header + "30,180,20,0,0.5," + bad + "\n", "t.csv");
            FAIL() << bad;
        } catch (const DataError& e) {
            EXPECT_NE(std::string(e.what()).find("t.csv:2: column measurement: '" +
                                                 std::string(bad) + "' is not a"),
                      std::string::npos)
                << e.what();
        }
    }
}
