// Live compensation against the offline model: every kind compensate steps is written to fit.json's
// form, read back, streamed sample by sample and compared with predicted_error on the same samples;
// missing readings hold, late samples are skipped, and a stream without a model's column is
// refused naming it; the output's writer drops whole lines, announced, for a reader that does not
// read, instead of waiting for it.
#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <limits>
#include <sstream>
#include <thread>

#include "core/errors.hpp"
#include "fitting/compensation.hpp"
#include "fitting/models.hpp"
#include "io/fit_model_in.hpp"
#include "io/fitting_out.hpp"
#include "io/sample_stream.hpp"
#include "synthetic.hpp"
#include "tests/fitting/deployed.hpp"

namespace {

using namespace tt::fitting;
using nlohmann::json;
using tt::fitting::test::columns_of;
using tt::fitting::test::fit_doc;
using tt::fitting::test::sample_of;
constexpr double um = 1e-6;
constexpr double missing_value = std::numeric_limits<double>::quiet_NaN();

Eigen::VectorXd increment(const Group& g, int k) {
  return g.temperature.col(k).array() - g.temperature(0, k);
}

/// Four runs of six sensors and a spindle speed; z lags t1, depends on t3 and on the speed.
std::vector<Group> runs() {
  auto groups = test::campaign(
      4, 31,
      [](const Group& g) {
        return Eigen::VectorXd(1.5 * um * low_pass(g.time, increment(g, 0), 2400.0).array() -
                               0.8 * um * increment(g, 2).array());
      },
      0.05 * um);
  for (Group& g : groups) {
    // A speed that follows the heat of sensor 1, on a non-uniform clock.
    g.inputs = (increment(g, 0) * 400.0).array() + 1000.0;
    g.input_names = {"speed_rpm"};
    for (Eigen::Index i = 1; i < g.time.size(); ++i) g.time(i) += 7.0 * std::sin(0.3 * i);
  }
  return groups;
}

/// The streamed predictions of a group [m], through fit.json and back.
Eigen::VectorXd streamed(const FittedModel& model, const Group& g) {
  const auto deployed = tt::io::deployed_models(fit_doc(model), "fit.json");
  EXPECT_EQ(deployed.size(), 1u);
  EXPECT_NEAR(deployed[0].uncertainty, std::sqrt((0.09 + 0.16) / 2) * um, 1e-15);
  EXPECT_EQ(deployed[0].uncertainty_groups, "test");
  Compensator c({deployed[0].model}, columns_of(g));
  Eigen::VectorXd out(g.time.size());
  for (Eigen::Index i = 0; i < g.time.size(); ++i) {
    const LiveStep& s = c.next(g.time(i), sample_of(g, i));
    EXPECT_EQ(s.status, SampleStatus::ok);
    out(i) = s.predicted(0);
  }
  return out;
}

void expect_same(const Eigen::VectorXd& live, const Eigen::VectorXd& offline) {
  ASSERT_EQ(live.size(), offline.size());
  const double scale = std::max(offline.cwiseAbs().maxCoeff(), 1e-9);
  EXPECT_LE((live - offline).cwiseAbs().maxCoeff(), 1e-9 * scale);
}

struct Kind {
  const char* name;
  ModelSpec spec;
  std::vector<int> sensors;
};

std::vector<Kind> kinds() {
  std::vector<Kind> k;
  ModelSpec none;
  none.kind = ModelKind::no_compensation;
  k.push_back({"no_compensation", none, {0, 2}});
  k.push_back({"least_squares", ModelSpec{}, {0, 2, 4}});
  ModelSpec ridge;
  ridge.kind = ModelKind::ridge;
  ridge.ridge_lambda = 1e-3;
  k.push_back({"ridge", ridge, {0, 1, 2}});
  ModelSpec lag;
  lag.kind = ModelKind::distributed_lag;
  lag.time_constants = {600.0, 3600.0};
  lag.ridge_lambda = 1e-4;
  k.push_back({"distributed_lag", lag, {0, 2}});
  ModelSpec lag_speed = lag;
  lag_speed.use_inputs = true;
  k.push_back({"distributed_lag_speed", lag_speed, {0, 2, 3}});
  ModelSpec ridge_speed = ridge;
  ridge_speed.use_inputs = true;
  k.push_back({"ridge_speed", ridge_speed, {0, 2}});
  ModelSpec ppr;
  ppr.kind = ModelKind::projection_pursuit;
  ppr.ppr.directions = 40;
  ppr.ppr.max_terms = 2;
  k.push_back({"projection_pursuit", ppr, {0, 2}});
  return k;
}

}  // namespace

TEST(Compensation, EveryKindStreamedThroughFitJsonMatchesTheOfflineModel) {
  const auto groups = runs();
  const std::vector<Group> fitting(groups.begin(), groups.begin() + 3);
  const Group& held_out = groups.back();
  for (const Kind& k : kinds()) {
    SCOPED_TRACE(k.name);
    const FittedModel model = fitted_model(k.spec, fitting, k.sensors, 0);
    expect_same(streamed(model, held_out), predicted_error(model, held_out));
    if (k.spec.kind != ModelKind::no_compensation) {
      EXPECT_GT(predicted_error(model, held_out).cwiseAbs().maxCoeff(), 1.0 * um);
    }
  }
}

TEST(Compensation, MissingReadingHoldsTheLastGoodValueAndSaysWhich) {
  const auto groups = runs();
  ModelSpec lag;
  lag.kind = ModelKind::distributed_lag;
  lag.time_constants = {600.0};
  lag.use_inputs = true;
  const FittedModel model = fitted_model(lag, {groups[0], groups[1]}, {0, 2}, 0);
  Group g = groups[2];
  const auto deployed = tt::io::deployed_models(fit_doc(model), "fit.json");
  // A stream with an extra column the model does not read, in another order.
  std::vector<std::string> columns = columns_of(g);
  std::reverse(columns.begin(), columns.end());
  Compensator c({deployed[0].model}, columns);
  const auto column = [&](const std::string& name) {
    return static_cast<Eigen::Index>(std::find(columns.begin(), columns.end(), name) -
                                     columns.begin());
  };
  Group filled = g;
  const Eigen::Index gap = 40;
  Eigen::VectorXd live(g.time.size());
  for (Eigen::Index i = 0; i < g.time.size(); ++i) {
    Eigen::VectorXd v = sample_of(g, i).reverse();
    if (i == gap || i == gap + 1) {
      v(column("t3")) = i == gap ? missing_value : std::numeric_limits<double>::infinity();
      v(column("speed_rpm")) = i == gap ? missing_value : v(column("speed_rpm"));
      filled.temperature(i, 2) = filled.temperature(gap - 1, 2);
      if (i == gap) filled.inputs(i, 0) = filled.inputs(gap - 1, 0);
    }
    if (i == gap + 2) v(column("t6")) = missing_value;  // not read by the model: no effect
    const LiveStep& s = c.next(g.time(i), v);
    live(i) = s.predicted(0);
    if (i == gap) {
      EXPECT_EQ(s.status, SampleStatus::held);
      // in the stream's column order
      EXPECT_EQ(tt::io::status_text(s, columns), "held:speed_rpm;t3");
    } else if (i == gap + 1) {
      EXPECT_EQ(tt::io::status_text(s, columns), "held:t3");
    } else {  // including gap + 2, whose missing t6 the model does not read
      EXPECT_EQ(s.status, SampleStatus::ok) << i;
    }
  }
  expect_same(live, predicted_error(model, filled));
  EXPECT_GT((live - predicted_error(model, g)).cwiseAbs().maxCoeff(), 0.0);
}

TEST(Compensation, StatusTextPutsWhatTheObserverSaysFirst) {
  // The observer's word on the machine (recalibrate) and on its sensors (sensor_fault, by name)
  // in place of ok, and before a sample's own status.
  const std::vector<std::string> columns{"speed_rpm", "T02", "T11"};
  LiveStep s;
  s.status = SampleStatus::ok;
  EXPECT_EQ(tt::io::status_text(s, columns), "ok");
  s.faulty = {2};
  EXPECT_EQ(tt::io::status_text(s, columns), "sensor_fault:T11");
  s.faulty = {2, 1};
  s.recalibrate = true;
  EXPECT_EQ(tt::io::status_text(s, columns), "recalibrate|sensor_fault:T11;T02");
  s.status = SampleStatus::held;
  s.held = {0};
  EXPECT_EQ(tt::io::status_text(s, columns), "recalibrate|sensor_fault:T11;T02|held:speed_rpm");
  s.faulty.clear();
  EXPECT_EQ(tt::io::status_text(s, columns), "recalibrate|held:speed_rpm");
  EXPECT_EQ(tt::io::model_status(false, {}), "");
}

TEST(Compensation, AWriterWhoseReaderDoesNotReadDropsWholeLinesAndSaysHowMany) {
  // 20 000 lines to a pipe nobody reads while they are written: every call returns (a writer
  // that waited would hang here: the alarm ends the test), at most 8 KiB and a line are held,
  // and what the reader then gets is whole lines in order, each gap announced by the line after
  // it, none unannounced.
  int fds[2];
  ASSERT_EQ(::pipe(fds), 0);
  ::alarm(120);
  tt::io::BufferedWriter writer(fds[1], "the test's pipe", 8192);
  const int lines = 20000;
  const std::string padding(40, 'x');
  for (int i = 0; i < lines; ++i) {
    const std::size_t gap = writer.drop_behind();
    const std::string status = gap ? tt::io::with_dropped("ok", gap) : "ok";
    writer.text += std::to_string(i) + "," + status + "," + padding + "\n";
    writer.write_ready();
    ASSERT_LE(writer.held(), 8192u + 60u) << "line " << i;
  }
  ::alarm(0);
  std::string got;
  std::thread reader([&] {
    char buffer[4096];
    for (ssize_t n; (n = ::read(fds[0], buffer, sizeof buffer)) > 0;) got.append(buffer, n);
  });
  writer.flush();
  ::close(fds[1]);
  reader.join();
  ::close(fds[0]);
  std::istringstream in(got);
  int expected = 0, gaps = 0;
  for (std::string line; std::getline(in, line);) {
    const std::size_t comma = line.find(','), second = line.find(',', comma + 1);
    ASSERT_NE(second, std::string::npos) << line;
    ASSERT_EQ(line.substr(second + 1), padding) << line;
    const int i = std::stoi(line.substr(0, comma));
    const std::string status = line.substr(comma + 1, second - comma - 1);
    const int gap = status == "ok" ? 0 : std::stoi(status.substr(status.find(':') + 1));
    ASSERT_EQ(i, expected + gap) << line;
    gaps += gap > 0;
    expected = i + 1;
  }
  EXPECT_EQ(expected, lines);
  EXPECT_GT(gaps, 0);
  EXPECT_EQ(tt::io::with_dropped("held:T07", 3), "held:T07|dropped:3");
}

TEST(Compensation, WaitsForACompleteFirstSampleAndSkipsLateOnes) {
  const auto groups = runs();
  const FittedModel model = fitted_model(ModelSpec{}, {groups[0], groups[1]}, {0, 1}, 0);
  const Group& g = groups[2];
  const auto deployed = tt::io::deployed_models(fit_doc(model), "fit.json");
  Compensator c({deployed[0].model}, columns_of(g));
  Eigen::VectorXd first = sample_of(g, 0);
  first(1) = missing_value;
  const LiveStep& w = c.next(g.time(0) - 5.0, first);
  EXPECT_EQ(w.status, SampleStatus::waiting);
  EXPECT_TRUE(std::isnan(w.predicted(0)));
  EXPECT_EQ(tt::io::status_text(w, columns_of(g)), "waiting:t2");
  Eigen::VectorXd live(g.time.size());
  for (Eigen::Index i = 0; i < g.time.size(); ++i) {
    live(i) = c.next(g.time(i), sample_of(g, i)).predicted(0);
    if (i == 10) {
      const LiveStep& late = c.next(g.time(i), sample_of(g, i + 1));
      EXPECT_EQ(late.status, SampleStatus::late);
      EXPECT_EQ(late.predicted(0), live(i));
      EXPECT_EQ(c.next(missing_value, sample_of(g, i + 1)).status, SampleStatus::late);
    }
  }
  expect_same(live, predicted_error(model, g));
}

TEST(Compensation, StreamWithoutAModelsColumnIsRefusedNamingIt) {
  const auto groups = runs();
  ModelSpec spec;
  spec.use_inputs = true;
  const FittedModel model = fitted_model(spec, {groups[0], groups[1]}, {0, 3}, 0);
  const auto deployed = tt::io::deployed_models(fit_doc(model), "fit.json");
  for (const std::string missing : {"t4", "speed_rpm"}) {
    std::vector<std::string> columns = columns_of(groups[2]);
    columns.erase(std::find(columns.begin(), columns.end(), missing));
    try {
      Compensator c({deployed[0].model}, columns);
      ADD_FAILURE() << "a stream without " << missing << " was taken";
    } catch (const tt::core::DataError& e) {
      EXPECT_NE(std::string(e.what()).find("column '" + missing + "' is missing"),
                std::string::npos)
          << e.what();
    }
  }
}

TEST(Compensation, FitJsonOfTheNetworkOrWithBadTermsIsRefusedNamingWhy) {
  const auto groups = runs();
  const FittedModel model = fitted_model(ModelSpec{}, {groups[0], groups[1]}, {0, 1}, 0);
  json doc = fit_doc(model);
  doc["targets"][0]["chosen"]["coefficients"]["kind"] = "cnn_bigru_attention";
  EXPECT_THROW(
      {
        try {
          tt::io::deployed_models(doc, "fit.json");
        } catch (const tt::core::DataError& e) {
          EXPECT_NE(std::string(e.what()).find("cnn_bigru_attention"), std::string::npos);
          throw;
        }
      },
      tt::core::DataError);
  doc = fit_doc(model);
  doc["targets"][0]["chosen"]["coefficients"]["terms"][1]["name"] = "dT[t9]";
  EXPECT_THROW(tt::io::deployed_models(doc, "fit.json"), tt::core::DataError);
  doc = fit_doc(model);
  doc["targets"][0]["chosen"]["coefficients"].erase("intercept_um");
  EXPECT_THROW(tt::io::deployed_models(doc, "fit.json"), tt::core::DataError);
}

TEST(Compensation, StreamLinesParseEmptyAndTextCellsAsMissing) {
  EXPECT_EQ(tt::io::stream_columns("time_s,speed_rpm,T07,dx\r", "s"),
            (std::vector<std::string>{"speed_rpm", "T07", "dx"}));
  // A spreadsheet's UTF-8 byte-order mark before the header, as the measured-data reader takes it.
  EXPECT_EQ(tt::io::stream_columns("\xEF\xBB\xBFtime_s,T07", "s"),
            (std::vector<std::string>{"T07"}));
  EXPECT_THROW(tt::io::stream_columns("t,T07", "s"), tt::core::DataError);
  EXPECT_THROW(tt::io::stream_columns("time_s,T07,T07", "s"), tt::core::DataError);
  Eigen::VectorXd v(3);
  double t = 0.0;
  ASSERT_TRUE(tt::io::parsed_sample("12.5,1500,,nan", t, v));
  EXPECT_EQ(t, 12.5);
  EXPECT_EQ(v(0), 1500.0);
  EXPECT_TRUE(std::isnan(v(1)) && std::isnan(v(2)));
  ASSERT_TRUE(tt::io::parsed_sample("13, 2e3 ,x,-1.25", t, v));
  EXPECT_EQ(v(0), 2000.0);
  EXPECT_TRUE(std::isnan(v(1)));
  EXPECT_EQ(v(2), -1.25);
  // A spreadsheet's quoted fields, names and numbers alike.
  EXPECT_EQ(tt::io::stream_columns("\"time_s\",\"T07\", \"dx\"", "s"),
            (std::vector<std::string>{"T07", "dx"}));
  ASSERT_TRUE(tt::io::parsed_sample("\"14\",\"2.5\",\"\",\" 7 \"", t, v));
  EXPECT_EQ(t, 14.0);
  EXPECT_EQ(v(0), 2.5);
  EXPECT_TRUE(std::isnan(v(1)));
  EXPECT_EQ(v(2), 7.0);
  EXPECT_FALSE(tt::io::parsed_sample("13,1,2", t, v));
  EXPECT_FALSE(tt::io::parsed_sample("13,1,2,3,4", t, v));
}
