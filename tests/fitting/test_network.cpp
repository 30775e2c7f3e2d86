// The CNN-BiGRU-attention model kind (seed 004) on a short synthetic campaign: it learns a lagged
// response better than a constant, gives the same weights and predictions twice for one seed,
// round-trips through its TorchScript file, and is tried only with its own sensor sets; one network
// trained on two targets at once (the patent's every-output model) serves both; read back from
// fit.json and its file, it is stepped live as compensate steps it.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>

#include "core/errors.hpp"
#include "fitting/compensation.hpp"
#include "fitting/models.hpp"
#include "fitting/selection.hpp"
#include "fitting/torch/network.hpp"
#include "io/fit_model_in.hpp"
#include "tests/fitting/deployed.hpp"
#include "tests/fitting/synthetic.hpp"

using namespace tt::fitting;
using tt::fitting::test::campaign;
using tt::fitting::test::increment;

namespace {

constexpr double um = 1e-6;

Eigen::VectorXd lagged_truth(const Group& g) {
  return 1.5 * um * low_pass(g.time, increment(g, 0), 2400.0).array() +
         0.5 * um * increment(g, 3).array();
}

/// A network small enough to train in seconds on 2 shared cores.
ModelSpec small_network(const std::string& method = "") {
  tt::torchnet::NetworkOptions o;
  o.window_steps = 8;
  o.conv_channels = 8;
  o.gru_hidden = 8;
  o.max_epochs = 40;
  o.patience = 10;
  o.batch_size = 32;
  o.learning_rate = 5e-3;
  o.seed = 7;
  return network_spec(o, 3600.0, method);
}

/// S_M of predicting each group's mean error: what a model must beat to be worth anything.
double constant_sm(const std::vector<Group>& groups) {
  std::vector<double> s;
  for (const Group& g : groups) {
    const Eigen::VectorXd e = g.error.col(0);
    s.push_back(residual_std((e.array() - e.mean()).matrix()));
  }
  return accuracy(s).sm;
}

class Network : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    groups_ = new std::vector<Group>(campaign(6, 91, lagged_truth, 0.1 * um, 4));
    model_ = new FittedModel(
        fitted_model(small_network(), group_subset(*groups_, {0, 1, 2, 3}), {0, 1, 2, 3}, 0));
  }
  static void TearDownTestSuite() {
    delete model_;
    delete groups_;
  }
  static std::vector<Group>* groups_;
  static FittedModel* model_;
};
std::vector<Group>* Network::groups_ = nullptr;
FittedModel* Network::model_ = nullptr;

}  // namespace

TEST_F(Network, BeatsAConstantOnHeldOutGroups) {
  const auto held_out = group_subset(*groups_, {4, 5});
  const Accuracy a = model_accuracy(*model_, held_out);
  EXPECT_LT(a.sm, 0.5 * constant_sm(held_out))
      << "network S_M " << a.sm / um << " um, constant " << constant_sm(held_out) / um << " um";
}

TEST_F(Network, SameSeedSameWeightsAndPredictions) {
  const FittedModel again =
      fitted_model(small_network(), group_subset(*groups_, {0, 1, 2, 3}), {0, 1, 2, 3}, 0);
  const auto& a = std::get<tt::torchnet::Network>(model_->body);
  const auto& b = std::get<tt::torchnet::Network>(again.body);
  ASSERT_FALSE(a.flat_weights().empty());
  EXPECT_EQ(a.flat_weights(), b.flat_weights());
  EXPECT_EQ(a.report().epochs, b.report().epochs);
  const Eigen::VectorXd pa = predicted_error(*model_, (*groups_)[5]);
  const Eigen::VectorXd pb = predicted_error(again, (*groups_)[5]);
  EXPECT_EQ(pa, pb);
}

TEST_F(Network, TorchScriptFileGivesTheSamePredictions) {
  const auto& net = std::get<tt::torchnet::Network>(model_->body);
  const auto file = std::filesystem::path(TT_BINARY_DIR) / "test_network_model.pt";
  net.save_torchscript(file);
  const Group& g = (*groups_)[5];
  const Eigen::MatrixXd x = feature_matrix(model_->features, g);
  std::vector<Eigen::Index> rows;
  for (Eigen::Index i = 0; i < x.rows(); i += 7) rows.push_back(i);
  const auto windows =
      tt::torchnet::windows_at(x, net.options().window_steps, net.options().window_stride, rows);
  const Eigen::MatrixXd loaded = tt::torchnet::torchscript_prediction(file, windows);
  const Eigen::VectorXd in_memory = predicted_error(*model_, g);
  ASSERT_EQ(loaded.rows(), static_cast<Eigen::Index>(rows.size()));
  for (std::size_t k = 0; k < rows.size(); ++k) {
    EXPECT_NEAR(loaded(static_cast<Eigen::Index>(k), 0), in_memory(rows[k]), 1e-4 * um);
    EXPECT_NEAR(net.window_prediction(windows[k])(0), in_memory(rows[k]), 1e-4 * um);
  }
  std::filesystem::remove(file);
}

TEST_F(Network, TriedOnlyWithItsSensorMethod) {
  const std::vector<SensorSet> sets{{"correlation", {0, 3}}, {"grey_relational", {0, 1, 3}}};
  const Selection s =
      selection_on_validation(group_subset(*groups_, {0, 1, 2}), group_subset(*groups_, {3}), 0,
                              sets, {ModelSpec{}, small_network("grey_relational")});
  ASSERT_EQ(s.candidates.size(), 4u);
  EXPECT_FALSE(s.candidates[1].model.has_value());  // network x correlation
  EXPECT_NE(s.candidates[1].failure.find("not tried"), std::string::npos);
  ASSERT_TRUE(s.candidates[3].model.has_value()) << s.candidates[3].failure;
  EXPECT_EQ(s.candidates[3].model->features.sensors, (std::vector<int>{0, 1, 3}));
}

TEST(NetworkOfEveryOutput, OneNetworkPredictsEachTargetAndBeatsAConstant) {
  // Two targets with different lags: one network with an output per target.
  auto groups = campaign(6, 91, lagged_truth, 0.1 * um, 4);
  for (std::size_t i = 0; i < groups.size(); ++i)
    tt::fitting::test::add_target(
        groups[i], "x",
        [](const Group& g) -> Eigen::VectorXd {
          return -2.0 * um * low_pass(g.time, increment(g, 1), 900.0).array();
        },
        0.1 * um, 2000, i);
  const auto fit = group_subset(groups, {0, 1, 2, 3});
  const auto models = fitted_network_models(small_network(), fit, {0, 1, 2, 3}, {1, 0});
  ASSERT_EQ(models.size(), 2u);
  EXPECT_EQ(models[0].target, 1);
  EXPECT_EQ(models[0].output, 0);
  EXPECT_EQ(models[1].target, 0);
  EXPECT_EQ(models[1].output, 1);
  const auto& a = std::get<tt::torchnet::Network>(models[0].body);
  const auto& b = std::get<tt::torchnet::Network>(models[1].body);
  EXPECT_EQ(a.outputs(), 2);
  EXPECT_EQ(a.flat_weights(), b.flat_weights());  // one training, shared
  const Group& g = groups[5];
  const Eigen::MatrixXd both = a.prediction(feature_matrix(models[0].features, g));
  EXPECT_EQ(predicted_error(models[0], g), Eigen::VectorXd(both.col(0)));
  EXPECT_EQ(predicted_error(models[1], g), Eigen::VectorXd(both.col(1)));
  const auto held_out = group_subset(groups, {4, 5});
  for (const auto& m : models) {
    std::vector<double> s;
    for (const Group& h : held_out) {
      const Eigen::VectorXd e = h.error.col(m.target);
      s.push_back(residual_std((e.array() - e.mean()).matrix()));
    }
    EXPECT_LT(model_accuracy(m, held_out).sm, 0.5 * accuracy(s).sm) << m.target_name;
  }
  // The same seed gives the same network.
  const auto again = fitted_network_models(small_network(), fit, {0, 1, 2, 3}, {1, 0});
  EXPECT_EQ(std::get<tt::torchnet::Network>(again[0].body).flat_weights(), a.flat_weights());
  // One scale for both outputs: the standardisation keeps their ratio of sizes.
  ModelSpec common = small_network();
  common.network.options.common_output_scale = true;
  const auto scaled = fitted_network_models(common, fit, {0, 1, 2, 3}, {1, 0});
  const auto& c = std::get<tt::torchnet::Network>(scaled[0].body);
  EXPECT_EQ(c.output_scale()(0), c.output_scale()(1));
  EXPECT_NE(a.output_scale()(0), a.output_scale()(1));
  EXPECT_NEAR(c.output_scale().squaredNorm(), a.output_scale().squaredNorm(),
              1e-12 * a.output_scale().squaredNorm());
  EXPECT_THROW(fitted_network_models(small_network(), fit, {0, 1}, {0, 0}), tt::core::DataError);
  EXPECT_THROW(fitted_network_models(ModelSpec{}, fit, {0, 1}, {0, 1}), tt::core::DataError);
}

TEST_F(Network, WeightDecayShrinksTheWeightsAndStaysDeterministic) {
  ModelSpec spec = small_network();
  spec.network.options.weight_decay = 1.0;
  const auto fit = group_subset(*groups_, {0, 1, 2, 3});
  const FittedModel a = fitted_model(spec, fit, {0, 1, 2, 3}, 0);
  const FittedModel b = fitted_model(spec, fit, {0, 1, 2, 3}, 0);
  const auto norm = [](const FittedModel& m) {
    double sum = 0.0;
    for (float w : std::get<tt::torchnet::Network>(m.body).flat_weights()) sum += double(w) * w;
    return std::sqrt(sum);
  };
  EXPECT_EQ(std::get<tt::torchnet::Network>(a.body).flat_weights(),
            std::get<tt::torchnet::Network>(b.body).flat_weights());
  EXPECT_LT(norm(a), norm(*model_));
  EXPECT_NE(model_label(spec).find("wd=1"), std::string::npos) << model_label(spec);
}

TEST(NetworkOptions, BadSettingsNameTheKey) {
  const auto groups = campaign(3, 5, lagged_truth, 0.1 * um, 4);
  ModelSpec spec = small_network();
  spec.network.options.kernel_size = 4;
  try {
    fitted_model(spec, groups, {0, 1}, 0);
    FAIL() << "an even kernel was accepted";
  } catch (const tt::core::DataError& e) {
    EXPECT_NE(std::string(e.what()).find("kernel_size = 4"), std::string::npos) << e.what();
  }
  spec = small_network();
  spec.network.options.weight_decay = -0.1;
  try {
    fitted_model(spec, groups, {0, 1}, 0);
    FAIL() << "a negative weight decay was accepted";
  } catch (const tt::core::DataError& e) {
    EXPECT_NE(std::string(e.what()).find("weight_decay"), std::string::npos) << e.what();
  }
}

TEST(NetworkWithLinearSkip, LearnsWhatTheLinearModelLeavesAndRoundTrips) {
  // A lagged truth: a static ridge skip misses the lag, the network's windows carry it.
  const auto groups = campaign(6, 91, lagged_truth, 0.1 * um, 4);
  const auto fit = group_subset(groups, {0, 1, 2, 3});
  const auto held_out = group_subset(groups, {4, 5});
  ModelSpec spec = small_network();
  spec.network.linear_skip = true;
  spec.ridge_lambda = 1e-3;
  ModelSpec ridge;
  ridge.kind = ModelKind::ridge;
  ridge.ridge_lambda = 1e-3;
  ridge.reject_gross_errors = false;
  const double linear_sm = model_accuracy(fitted_model(ridge, fit, {0, 1, 2, 3}, 0), held_out).sm;
  const FittedModel a = fitted_model(spec, fit, {0, 1, 2, 3}, 0);
  const FittedModel b = fitted_model(spec, fit, {0, 1, 2, 3}, 0);
  const auto& net = std::get<tt::torchnet::Network>(a.body);
  ASSERT_TRUE(net.linear_skip().has_value());
  EXPECT_EQ(net.linear_skip()->weights.cols(), 4);
  EXPECT_EQ(net.flat_weights(), std::get<tt::torchnet::Network>(b.body).flat_weights());
  EXPECT_EQ(predicted_error(a, groups[5]), predicted_error(b, groups[5]));
  const double network_sm = model_accuracy(a, held_out).sm;
  EXPECT_LT(network_sm, 0.5 * constant_sm(held_out));
  EXPECT_LT(network_sm, linear_sm)
      << "network " << network_sm / um << " um, its ridge alone " << linear_sm / um
      << " um, best epoch " << net.report().best_epoch;
  EXPECT_NE(model_label(spec).find("linear_skip"), std::string::npos) << model_label(spec);
  // With lagged features the skip is a distributed-lag model and the windows read the lags too.
  spec.time_constants = {2400.0};
  const FittedModel lagged = fitted_model(spec, fit, {0, 1, 2, 3}, 0);
  EXPECT_EQ(std::get<tt::torchnet::Network>(lagged.body).linear_skip()->weights.cols(), 8);
  // The skip is inside the TorchScript file.
  const auto file = std::filesystem::path(TT_BINARY_DIR) / "test_network_skip.pt";
  net.save_torchscript(file);
  const Eigen::MatrixXd x = feature_matrix(a.features, groups[5]);
  std::vector<Eigen::Index> rows;
  for (Eigen::Index i = 0; i < x.rows(); i += 11) rows.push_back(i);
  const Eigen::MatrixXd loaded = tt::torchnet::torchscript_prediction(
      file,
      tt::torchnet::windows_at(x, net.options().window_steps, net.options().window_stride, rows));
  const Eigen::VectorXd in_memory = predicted_error(a, groups[5]);
  for (std::size_t k = 0; k < rows.size(); ++k)
    EXPECT_NEAR(loaded(static_cast<Eigen::Index>(k), 0), in_memory(rows[k]), 1e-4 * um);
  std::filesystem::remove(file);
}

TEST(NetworkWithLinearSkip, ChoosesItsOwnStrengthOnlyOnAContinuousRun) {
  // Given several groups (a fold of the blocked evaluation) the skip keeps the spec's strength,
  // which that evaluation chose; given one run it chooses among the grid on held-out time blocks
  // of it, and a clean linear truth does not want the spec's heavy shrinkage.
  const auto groups = campaign(6, 91, lagged_truth, 0.1 * um, 4);
  ModelSpec spec = small_network();
  spec.network.linear_skip = true;
  spec.ridge_lambda = 10.0;
  const auto several = fitted_model(spec, group_subset(groups, {0, 1, 2, 3}), {0, 1, 2, 3}, 0);
  const auto& kept = std::get<tt::torchnet::Network>(several.body).linear_skip()->ridge_lambda;
  ASSERT_EQ(kept.size(), 1);
  EXPECT_EQ(kept(0), 10.0);
  const auto one = fitted_model(spec, group_subset(groups, {0}), {0, 1, 2, 3}, 0);
  const auto& own = std::get<tt::torchnet::Network>(one.body).linear_skip()->ridge_lambda;
  ASSERT_EQ(own.size(), 1);
  EXPECT_LT(own(0), 10.0);
  EXPECT_GE(own(0), 1e-6);
}

// The network live: fit.json's record of it and its TorchScript file read back and stepped
// sample by sample by the compensator give the in-memory model's predictions.

namespace {

/// The campaign with a spindle speed that follows sensor 1's heat, read as an operating input.
std::vector<Group> with_speed(std::vector<Group> groups) {
  for (Group& g : groups) {
    g.inputs = (increment(g, 0) * 400.0).array() + 1000.0;
    g.input_names = {"speed_rpm"};
  }
  return groups;
}

/// A network with the parts compensate must carry: a lagged feature, an input, and a linear skip
/// when asked (with one, the network may add next to nothing to the skip).
FittedModel deployable_network(const std::vector<Group>& fit, bool skip) {
  ModelSpec spec = small_network();
  spec.network.linear_skip = skip;
  spec.ridge_lambda = 1e-3;
  spec.time_constants = {2400.0};
  spec.use_inputs = true;
  return fitted_model(spec, fit, {0, 1, 3}, 0);
}

/// A fresh directory under the build tree.
std::filesystem::path fresh_dir(const std::string& name) {
  const auto dir = std::filesystem::path(TT_BINARY_DIR) / name;
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir);
  return dir;
}

/// The DataError message deployed_models gives, or "" when it reads the document.
std::string refusal(const nlohmann::json& doc, const std::filesystem::path& dir) {
  try {
    tt::io::deployed_models(doc, "fit.json", dir);
  } catch (const tt::core::DataError& e) {
    return e.what();
  }
  return "";
}

}  // namespace

TEST(NetworkCompensation, StreamedFromFitJsonAndItsFileGivesTheOfflinePredictions) {
  const auto groups = with_speed(campaign(5, 91, lagged_truth, 0.1 * um, 4));
  const FittedModel model = deployable_network(group_subset(groups, {0, 1, 2}), false);
  const auto dir = fresh_dir("test_network_compensation");
  std::get<tt::torchnet::Network>(model.body).save_torchscript(dir / "network_z.pt");
  const auto deployed = tt::io::deployed_models(tt::fitting::test::fit_doc(model), "fit.json", dir);
  ASSERT_EQ(deployed.size(), 1u);
  const FittedModel& read = deployed[0].model;
  const auto& net = std::get<tt::torchnet::Network>(read.body);
  EXPECT_EQ(net.options().sample_interval_s, 60.0);
  EXPECT_EQ(net.options().window_stride, 9);  // 3600 s over 7 spacings of 60 s, rounded
  EXPECT_GT(std::get<tt::torchnet::Network>(model.body).report().best_epoch, 0);
  EXPECT_EQ(read.features.time_constants, std::vector<double>{2400.0});
  const Group& held_out = groups[4];
  const Eigen::VectorXd offline = predicted_error(model, held_out);
  ASSERT_GT(offline.cwiseAbs().maxCoeff(), 0.5 * um);
  // Sample by sample: every sample evaluated, then once per half hour and held between.
  for (const double every : {0.0, 1800.0}) {
    SCOPED_TRACE(every);
    Compensator c({read}, tt::fitting::test::columns_of(held_out), {}, every);
    double evaluated = -1e300, held = 0.0;
    int evaluations = 0;
    for (Eigen::Index i = 0; i < held_out.time.size(); ++i) {
      const LiveStep& s = c.next(held_out.time(i), tt::fitting::test::sample_of(held_out, i));
      ASSERT_EQ(s.status, SampleStatus::ok);
      if (held_out.time(i) - evaluated >= every) {
        evaluated = held_out.time(i);
        held = offline(i);
        ++evaluations;
      }
      EXPECT_NEAR(s.predicted(0), held, 1e-4 * um) << "sample " << i;
    }
    EXPECT_EQ(evaluations, every > 0.0 ? 11 : static_cast<int>(held_out.time.size()));
  }
}

TEST(NetworkCompensation, AWindowOfADenseStreamReadsItsPastAtTheTrainingSpacing) {
  // A row linear in time is read back exactly by interpolation, wherever the entries fall; a
  // stream 600 times denser than the rows kept holds one row per keep_every.
  WindowHistory history(8, 540.0, 60.0);
  const auto row = [](double t) { return Eigen::Vector2d(t, 3.0 - 2.0 * t); };
  for (int i = 0; i <= 36000; ++i) {
    const double t = 0.1 * i;
    history.push(t, row(t));
    if (i % 9001 != 0 && i != 36000) continue;
    const Eigen::MatrixXd w = history.window();
    ASSERT_EQ(w.rows(), 8);
    for (int j = 0; j < 8; ++j) {
      const double at = std::max(0.0, t - (7 - j) * 540.0);  // the first row before the start
      EXPECT_NEAR(w(j, 0), row(at)(0), 1e-9) << "t " << t << " entry " << j;
      EXPECT_NEAR(w(j, 1), row(at)(1), 1e-9) << "t " << t << " entry " << j;
    }
  }
  EXPECT_LE(history.kept(), 7u * 9u + 2u);
  EXPECT_THROW(WindowHistory(8, 0.0, 60.0), tt::core::DataError);
}

TEST(NetworkCompensation, AMissingOrForeignNetworkFileIsRefusedNamingIt) {
  const auto groups = with_speed(campaign(5, 91, lagged_truth, 0.1 * um, 4));
  const FittedModel model = deployable_network(group_subset(groups, {0, 1, 2}), true);
  const auto dir = fresh_dir("test_network_compensation_refused");
  const nlohmann::json doc = tt::fitting::test::fit_doc(model);
  EXPECT_NE(refusal(doc, dir).find("network_z.pt"), std::string::npos) << refusal(doc, dir);
  // The file of a network fitted on other runs.
  const FittedModel other = deployable_network(group_subset(groups, {3, 4}), true);
  std::get<tt::torchnet::Network>(other.body).save_torchscript(dir / "network_z.pt");
  EXPECT_NE(refusal(doc, dir).find("another fit"), std::string::npos) << refusal(doc, dir);
  std::get<tt::torchnet::Network>(model.body).save_torchscript(dir / "network_z.pt");
  EXPECT_EQ(refusal(doc, dir), "");
  // The skip read back from the file's buffers is the trained one (to float32).
  const auto read = tt::io::deployed_models(doc, "fit.json", dir);
  const auto& skip = std::get<tt::torchnet::Network>(read[0].model.body).linear_skip();
  ASSERT_TRUE(skip.has_value());
  const auto& trained = *std::get<tt::torchnet::Network>(model.body).linear_skip();
  ASSERT_EQ(skip->weights.rows(), trained.weights.rows());
  ASSERT_EQ(skip->weights.cols(), trained.weights.cols());
  EXPECT_LE((skip->weights - trained.weights).cwiseAbs().maxCoeff(),
            1e-6 * trained.weights.cwiseAbs().maxCoeff());
  EXPECT_LE((skip->intercept - trained.intercept).cwiseAbs().maxCoeff(),
            1e-6 * std::max(1e-9, trained.intercept.cwiseAbs().maxCoeff()));
  // Not a TorchScript file.
  std::ofstream(dir / "network_z.pt") << "not a network\n";
  EXPECT_NE(refusal(doc, dir).find("not a TorchScript network"), std::string::npos)
      << refusal(doc, dir);
  std::get<tt::torchnet::Network>(model.body).save_torchscript(dir / "network_z.pt");
  // fit.json's record of another network's inputs.
  nlohmann::json other_inputs = doc;
  other_inputs["targets"][0]["chosen"]["coefficients"]["input_mean_K"][0] = 9.0;
  EXPECT_NE(refusal(other_inputs, dir).find("input_mean_K does not match"), std::string::npos)
      << refusal(other_inputs, dir);
  // Where no directory is given (the CNC export), a network is not read.
  EXPECT_THROW(tt::io::deployed_models(doc, "fit.json"), tt::core::DataError);
}
