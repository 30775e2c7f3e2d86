// The compensation in the controllers' forms (fitting/cnc_export.hpp, io/cnc_model_in.hpp,
// io/cnc_out.hpp): each law against the model and against the analytic error of its form, the
// reader of fit.json's axis models (the cubic it builds, the keys it refuses), and the files.
#include <gtest/gtest.h>

#include <cmath>
#include <map>
#include <set>
#include <sstream>

#include "cnc_fixture.hpp"
#include "core/errors.hpp"
#include "fitting/cnc_export.hpp"
#include "io/cnc_model_in.hpp"
#include "io/cnc_out.hpp"
#include "io/fitting_out.hpp"

namespace {

using namespace tt::fitting;
using nlohmann::json;
using tt::test::fit_document;
using tt::test::linear_model;
constexpr double um = 1e-6;
constexpr double L = 1.25;  // half travel [m], as GM-1's X axis

/// Basis (1, dT[a], dT[b]); X feed axis over [-L, L]. dx: p^3 per K of a and p per K of b
/// [µm/m^k]; dy: p^2 per K of b; dz: a TCP drift only.
CncModel cubic_model() {
  CncModel m;
  m.basis = {"1", "dT[a]", "dT[b]"};
  m.features.sensor_names = {"a", "b"};
  m.features.sensors = {0, 1};
  m.feed_axis = "X";
  m.feed_direction = 0;
  m.travel_min = -L;
  m.travel_max = L;
  for (auto& t : m.tcp) t = Eigen::VectorXd::Zero(3);
  for (auto& c : m.axis) c = Eigen::MatrixXd::Zero(4, 3);
  m.axis[0](3, 1) = 1 * um;
  m.axis[0](1, 2) = 2 * um;
  m.axis[0](0, 0) = 0.5 * um;
  m.axis[1](2, 2) = 1 * um;
  m.tcp[2] << -1.0 * um, 3.0 * um, -2.0 * um;
  return m;
}

Eigen::MatrixXd state(double a, double b) {
  Eigen::MatrixXd s(1, 3);
  s << 1.0, a, b;
  return s;
}

TEST(CncLaw, LineIsTheLeastSquaresLineOfTheCubic) {
  const CncModel m = cubic_model();
  const LineLaw law = line_law(m);
  EXPECT_NEAR(law.reference, 0.0, 1e-15);
  // p^3 on [-L, L]: slope 3L^2/5, value 0 at the middle; p: slope 1.
  EXPECT_NEAR(law.slope[0](1), -0.6 * L * L * um, 1e-6 * um);
  EXPECT_NEAR(law.slope[0](2), -2 * um, 1e-9 * um);
  EXPECT_NEAR(law.value[0](0), -0.5 * um, 1e-12 * um);
  // The Y axis cannot follow X: its value is the mean of p^2 over the travel, L^2/3.
  EXPECT_NEAR(law.value[1](2), -L * L / 3 * um, 1e-5 * um);
  EXPECT_EQ(law.slope[1].cwiseAbs().maxCoeff(), 0.0);
  // The TCP drift passes through unchanged.
  EXPECT_NEAR(law.value[2](1), -3.0 * um, 1e-15);
  // What it leaves: |p^3 - 3L^2 p/5| is largest at the ends, 0.4 L^3 per K of a; p^2 - L^2/3
  // leaves 2L^2/3 per K of b; b's line in x is exact.
  const LawError ea = law_error(m, law, state(1.0, 0.0), 1001);
  EXPECT_NEAR(ea.max[0], 0.4 * L * L * L * um, 1e-3 * um);
  EXPECT_NEAR(ea.max[2], 0.0, 1e-18);
  const LawError eb = law_error(m, law, state(0.0, 1.0), 1001);
  EXPECT_NEAR(eb.max[0], 0.0, 1e-15);
  EXPECT_NEAR(eb.max[1], 2.0 / 3.0 * L * L * um, 1e-3 * um);
  // Linear in the state: the error of two kelvin of a is twice that of one.
  EXPECT_NEAR(law_error(m, law, state(2.0, 0.0), 1001).max[0], 2 * ea.max[0], 1e-15);
}

TEST(CncLaw, TableMatchesTheModelAtItsPointsAndWithinTheInterpolationBound) {
  const CncModel m = cubic_model();
  const int points = 11;
  const TableLaw t = table_law(m, points, 0.0, false);
  const double h = 2 * L / (points - 1);
  for (Eigen::Index i = 0; i < t.positions.size(); ++i)
    for (int d = 0; d < 3; ++d)
      EXPECT_NEAR(law_compensation(t, d, t.positions(i), state(1.3, -0.7).row(0).transpose()),
                  model_compensation(m, d, t.positions(i), state(1.3, -0.7).row(0).transpose()),
                  1e-18);
  // Linear interpolation of f leaves at most h^2/8 max|f''|: p^3 has |f''| <= 6L per K.
  const LawError e = law_error(m, t, state(1.0, 0.0), 2001);
  EXPECT_LE(e.max[0], h * h / 8 * 6 * L * um * (1 + 1e-9));
  EXPECT_GT(e.max[0], 0.5 * h * h / 8 * 6 * L * um);  // and it is of that size, not zero
  // Heidenhain's rounding to 0.1 µm adds at most half a unit.
  const TableLaw q = table_law(m, points, 0.1 * um, false);
  const LawError eq = law_error(m, q, state(1.0, 0.0), 2001);
  EXPECT_LE(eq.max[0], e.max[0] + 0.05 * um + 1e-15);
  EXPECT_THROW(table_law(m, 1, 0.0, false), tt::core::DataError);
}

TEST(CncLaw, PolynomialIsExactToItsCount) {
  const CncModel m = cubic_model();
  const double q = tt::fitting::kLinuxcncScaleMm * 1e-3;
  const PolynomialLaw law = polynomial_law(m, q, true);
  Eigen::MatrixXd states(3, 3);
  states << 1, 0, 0, 1, 2.5, -1.0, 1, -3.0, 4.0;
  const LawError e = law_error(m, law, states, 1001);
  for (int d = 0; d < 3; ++d) EXPECT_LE(e.max[static_cast<std::size_t>(d)], q * (1 + 1e-9));
  const LawError exact = law_error(m, polynomial_law(m, 0.0, false), states, 1001);
  for (int d = 0; d < 3; ++d) EXPECT_LT(exact.max[static_cast<std::size_t>(d)], 1e-18);
  EXPECT_THROW(law_error(m, law, Eigen::MatrixXd::Ones(1, 2), 11), tt::core::DataError);
}

TEST(CncBasis, UnionOfTheModelsRegressors) {
  const LinearBasis b = linear_basis({linear_model("dz", {"a", "b"}, 1 * um, {2 * um, 3 * um}),
                                      linear_model("dy", {"c", "a"}, 0.0, {4 * um, 5 * um})});
  ASSERT_EQ(b.names, (std::vector<std::string>{"1", "dT[a]", "dT[b]", "dT[c]"}));
  EXPECT_DOUBLE_EQ(b.coefficients(0, 0), 1 * um);
  EXPECT_DOUBLE_EQ(b.coefficients(0, 2), 3 * um);
  EXPECT_DOUBLE_EQ(b.coefficients(1, 1), 5 * um);
  EXPECT_DOUBLE_EQ(b.coefficients(1, 3), 4 * um);
  FittedModel ppr = linear_model("dx", {"a"}, 0.0, {1.0});
  ppr.spec.kind = ModelKind::projection_pursuit;
  ppr.body = PprModel{};
  EXPECT_THROW(linear_basis({ppr}), tt::core::DataError);
}

TEST(CncModelIn, AxisPolynomialFromTheAxisModels) {
  const tt::io::CncModelFile f = tt::io::cnc_model(fit_document(), "fit.json");
  const CncModel& m = f.model;
  ASSERT_EQ(m.basis, (std::vector<std::string>{"1", "dT[b]", "dT[a]"}));
  EXPECT_EQ(m.feed_axis, "X");
  EXPECT_DOUBLE_EQ(m.travel_min, -1.0);
  EXPECT_NEAR(m.axis[0](3, 2), 1 * um, 1e-12 * um);
  EXPECT_NEAR(m.axis[0](1, 2), 0.0, 1e-12 * um);
  EXPECT_NEAR(m.axis[1](0, 1), 2 * um, 1e-12 * um);
  EXPECT_NEAR(m.tcp[2](1), -4 * um, 1e-18);
  // The whole model at a state: dx at p = 0.5 with 2 K on a is -2 * 0.125 µm.
  Eigen::VectorXd b(3);
  b << 1.0, 0.0, 2.0;
  EXPECT_NEAR(model_compensation(m, 0, 0.5, b), -0.25 * um, 1e-12 * um);
}

void expect_refused(const json& doc, const std::string& fragment) {
  try {
    tt::io::cnc_model(doc, "fit.json");
    ADD_FAILURE() << "accepted; expected a DataError naming " << fragment;
  } catch (const tt::core::DataError& e) {
    EXPECT_NE(std::string(e.what()).find(fragment), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("fit.json"), std::string::npos) << e.what();
  }
}

TEST(CncModelIn, RefusesBadInputNamingTheKey) {
  json doc = fit_document();
  doc["axis"]["targets"]["A02_dy"].erase("coefficients");
  expect_refused(doc, "axis.targets.A02_dy.coefficients");
  doc = fit_document();
  doc["axis"]["positions_m"][1] = "x";
  expect_refused(doc, "axis.positions_m[1]");
  doc = fit_document();
  doc["axis"]["feed_axis"]["direction"] = "w";
  expect_refused(doc, "axis.feed_axis");
  doc = fit_document();
  doc["axis"]["targets"]["A03_dx"]["coefficients"]["terms"][0]["um_per_K"] = "hot";
  expect_refused(doc, "terms[0].um_per_K");
  doc = fit_document();
  doc["axis"]["positions_m"][1] = -1.0;  // two points at one position
  expect_refused(doc, "share their axis position");
  doc = fit_document();
  doc["axis"].erase("feed_axis");  // written before export existed
  expect_refused(doc, "run `thermotwin fit` again");
  doc = fit_document();
  doc["axis"]["degree"] = 2.5;
  expect_refused(doc, "axis.degree");
}

TEST(CncStates, BasisStatesAreTheIncrementsSinceTheFirstSample) {
  const CncModel m = cubic_model();
  Eigen::VectorXd t(3);
  t << 0.0, 10.0, 20.0;
  Eigen::MatrixXd v(3, 3);  // columns b, x, a
  v << 20.0, 0.0, 21.0, 20.5, 0.0, 22.0, 21.0, 0.0, 21.5;
  const Eigen::MatrixXd s = basis_states(m, {"b", "x", "a"}, t, v);
  Eigen::MatrixXd expected(3, 3);
  expected << 1, 0, 0, 1, 1.0, 0.5, 1, 0.5, 1.0;
  EXPECT_TRUE(s.isApprox(expected)) << s;
  try {
    basis_states(m, {"b", "x"}, t, v.leftCols(2));
    ADD_FAILURE() << "samples without sensor a accepted";
  } catch (const tt::core::DataError& e) {
    EXPECT_NE(std::string(e.what()).find("column 'a' is missing"), std::string::npos) << e.what();
  }
}

/// net lines of a HAL file: every output pin on one signal, every input pin fed once.
void expect_consistent_hal(const std::string& hal) {
  std::istringstream in(hal);
  std::string line;
  std::map<std::string, std::string> writer_of;  // signal -> writer pin
  std::set<std::string> readers, loaded, added;
  while (std::getline(in, line)) {
    std::istringstream w(line);
    std::string cmd;
    w >> cmd;
    if (cmd == "loadrt") {
      std::string comp, names;
      w >> comp >> names;
      std::stringstream list(names.substr(6));
      for (std::string n; std::getline(list, n, ',');) EXPECT_TRUE(loaded.insert(n).second) << n;
    } else if (cmd == "addf") {
      std::string f;
      w >> f;
      EXPECT_TRUE(loaded.count(f)) << f;
      added.insert(f);
    } else if (cmd == "net") {
      std::string sig, a, arrow, b;
      w >> sig >> a;
      if (a == "=>") {
        w >> b;
      } else {
        w >> arrow >> b;
        ASSERT_EQ(arrow, "=>") << line;
        EXPECT_TRUE(writer_of.emplace(sig, a).second) << "signal written twice: " << line;
      }
      EXPECT_TRUE(readers.insert(b).second) << "pin fed twice: " << line;
    }
  }
  EXPECT_EQ(loaded, added);
}

TEST(CncFiles, EachFormatWritesItsParameters) {
  const CncModel m = cubic_model();
  for (tt::fitting::CncFormat f :
       {tt::fitting::CncFormat::sinumerik, tt::fitting::CncFormat::twincat,
        tt::fitting::CncFormat::heidenhain, tt::fitting::CncFormat::linuxcnc}) {
    const ControllerLaw law = tt::fitting::controller_law(f, m, 21);
    const auto files = tt::io::cnc_files(f, m, law, "fit.json");
    ASSERT_FALSE(files.empty());
    std::string all;
    for (const auto& file : files) all += file.text;
    switch (f) {
      case tt::fitting::CncFormat::sinumerik:
        EXPECT_NE(all.find("MD32750 $MA_TEMP_COMP_TYPE[X1] = 3"), std::string::npos);
        EXPECT_NE(all.find("MD32750 $MA_TEMP_COMP_TYPE[Y1] = 1"), std::string::npos);
        EXPECT_NE(all.find("$SA_TEMP_COMP_SLOPE[X1]="), std::string::npos);
        EXPECT_NE(
            all.find("$SA_TEMP_COMP_ABS_VALUE[Z1]=0.001-0.003*($R100-$R200)+0.002*($R101-$R201)"),
            std::string::npos)
            << all;
        break;
      case tt::fitting::CncFormat::twincat: {
        // The CSV round trip: the table's X column for a at each position is the model's.
        std::istringstream csv(files[1].text);
        std::string line;
        std::getline(csv, line);
        EXPECT_EQ(line.rfind("position_mm,X_mm_per[1],X_mm_per[dT[a]]", 0), 0u) << line;
        int rows = 0;
        while (std::getline(csv, line)) {
          double p_mm = 0, c0 = 0, ca = 0;
          ASSERT_EQ(std::sscanf(line.c_str(), "%lf,%lf,%lf", &p_mm, &c0, &ca), 3);
          EXPECT_NEAR(ca, -std::pow(p_mm * 1e-3, 3) * 1e-3, 1e-12);
          ++rows;
        }
        EXPECT_EQ(rows, 21);
        EXPECT_NE(all.find("ST_PositionCompensationTableElement"), std::string::npos);
        break;
      }
      case tt::fitting::CncFormat::heidenhain:
        EXPECT_EQ(files.size(), 4u);  // a table per basis function and the PLC note
        EXPECT_EQ(files[1].name, "TT_B01.COM");
        EXPECT_NE(files[1].text.find("NR AXISPOS X Y Z"), std::string::npos);
        EXPECT_NE(all.find("CM 9231"), std::string::npos);
        break;
      case tt::fitting::CncFormat::linuxcnc:
        expect_consistent_hal(files[0].text);
        EXPECT_NE(all.find("axis.x.eoffset-counts"), std::string::npos);
        EXPECT_NE(all.find("setp axis.z.eoffset-enable 1"), std::string::npos);
        EXPECT_NE(all.find("OFFSET_AV_RATIO"), std::string::npos);
        break;
    }
  }
  EXPECT_THROW(tt::io::format_of("fanuc"), tt::core::DataError);
}

}  // namespace
