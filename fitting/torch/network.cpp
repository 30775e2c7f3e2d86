#include "fitting/torch/network.hpp"

#include <ATen/CPUGeneratorImpl.h>
#include <ATen/Parallel.h>
#include <omp.h>
#include <torch/script.h>
#include <torch/torch.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <fstream>
#include <limits>
#include <mutex>
#include <sstream>

#include "core/errors.hpp"
#include "fitting/torch/engine.hpp"

namespace tt::torchnet {

namespace {

/// Torch's thread count is process-wide and, with its OpenMP backend, set_num_threads also sets
/// the calling thread's OpenMP team size: every torch call holds this lock and restores the
/// caller's team size afterwards, so the project's own parallel loops keep their threads.
std::mutex& torch_lock() {
  static std::mutex m;
  return m;
}

class TorchThreads {
 public:
  // at::set_num_threads also resizes torch's pthreadpool, which is rebuilt on every change: it is
  // called only when the count changes; the OpenMP team size that torch's parallel loops read is
  // set (and restored) on every call, which costs nothing.
  explicit TorchThreads(int threads) : lock_(torch_lock()), saved_(omp_get_max_threads()) {
    static int torch_threads = 0;  // guarded by the lock
    threads = std::max(1, threads);
    if (torch_threads != threads) {
      at::set_num_threads(threads);
      torch_threads = threads;
    }
    omp_set_num_threads(threads);
  }
  ~TorchThreads() { omp_set_num_threads(std::max(1, saved_)); }
  TorchThreads(const TorchThreads&) = delete;
  TorchThreads& operator=(const TorchThreads&) = delete;

 private:
  std::lock_guard<std::mutex> lock_;
  int saved_;
};

struct NetImpl : torch::nn::Module {
  NetImpl(int inputs, int outputs, const NetworkOptions& o)
      : conv1(register_module("conv1", torch::nn::Conv1d(torch::nn::Conv1dOptions(
                                                             inputs, o.conv_channels, o.kernel_size)
                                                             .padding(o.kernel_size / 2)))),
        conv2(register_module(
            "conv2", torch::nn::Conv1d(
                         torch::nn::Conv1dOptions(o.conv_channels, o.conv_channels, o.kernel_size)
                             .padding(o.kernel_size / 2)))),
        norm(register_module("norm", torch::nn::BatchNorm1d(o.conv_channels))),
        gru(register_module("gru",
                            torch::nn::GRU(torch::nn::GRUOptions(o.conv_channels, o.gru_hidden)
                                               .num_layers(o.gru_layers)
                                               .bidirectional(true)
                                               .batch_first(true)))),
        key(register_module("key", torch::nn::Linear(2 * o.gru_hidden, 2 * o.gru_hidden))),
        head(register_module("head", torch::nn::Linear(2 * o.gru_hidden, outputs))) {}

  /// x: batch x steps x inputs, standardised; returns batch x outputs, standardised.
  torch::Tensor forward(torch::Tensor x) {
    x = x.transpose(1, 2);
    x = torch::relu(conv1->forward(x));
    x = torch::relu(conv2->forward(x));
    x = norm->forward(torch::max_pool1d(x, {2}, {2})).transpose(1, 2);
    const torch::Tensor y = std::get<0>(gru->forward(x));
    const torch::Tensor c = y.select(1, -1);
    // Feature attention: the weight of each of the 2·hidden features is the softmax of its term
    // of the dot product between the last GRU output and a learned projection of it; scaled so
    // that equal weights leave the output unchanged.
    const torch::Tensor a = torch::softmax(c * key->forward(c), 1);
    return head->forward(a * c * static_cast<double>(c.size(1)));
  }

  torch::nn::Conv1d conv1, conv2;
  // Batch normalisation, not layer normalisation: once trained it is a fixed affine map, so the
  // features keep the amplitude of the temperature rise (layer normalisation over the channels
  // would divide it out at every time step).
  torch::nn::BatchNorm1d norm;
  torch::nn::GRU gru;
  torch::nn::Linear key, head;
};
TORCH_MODULE(Net);

/// The same forward in TorchScript, reading the parameters registered by script_module.
std::string script_source(const NetworkOptions& o, int gru_tensors) {
  std::ostringstream s;
  const int pad = o.kernel_size / 2;
  s << "def forward(self, x: Tensor) -> Tensor:\n"
    << "    s = torch.linear(x[:, -1, :], self.skip_w, self.skip_b)\n"
    << "    x = (x - self.in_mean) / self.in_scale\n"
    << "    x = x.transpose(1, 2)\n"
    << "    x = torch.relu(torch.conv1d(x, self.conv1_w, self.conv1_b, [1], [" << pad << "]))\n"
    << "    x = torch.relu(torch.conv1d(x, self.conv2_w, self.conv2_b, [1], [" << pad << "]))\n"
    << "    x = torch.max_pool1d(x, [2], [2])\n"
    << "    x = torch.batch_norm(x, self.norm_w, self.norm_b, self.norm_mean, self.norm_var, "
       "False, 0.1, 1e-05, False).transpose(1, 2)\n"
    << "    h0 = torch.zeros([" << 2 * o.gru_layers << ", x.size(0), " << o.gru_hidden
    << "], dtype=x.dtype)\n"
    << "    y, h = torch.gru(x, h0, [";
  for (int i = 0; i < gru_tensors; ++i) s << (i ? ", " : "") << "self.gru_" << i;
  s << "], True, " << o.gru_layers << ", 0.0, False, True, True)\n"
    << "    c = y[:, -1, :]\n"
    << "    a = torch.softmax(c * torch.linear(c, self.key_w, self.key_b), 1)\n"
    << "    z = torch.linear(a * c * " << 2 * o.gru_hidden << ".0, self.head_w, self.head_b)\n"
    << "    return z * self.out_scale + self.out_mean + s\n";
  return s.str();
}

torch::Tensor float_tensor(const Eigen::VectorXd& v) {
  torch::Tensor t = torch::empty({v.size()}, torch::kFloat32);
  for (Eigen::Index i = 0; i < v.size(); ++i) t[i] = static_cast<float>(v(i));
  return t;
}

torch::Tensor float_tensor(const Eigen::MatrixXd& m) {
  torch::Tensor t = torch::empty({m.rows(), m.cols()}, torch::kFloat32);
  for (Eigen::Index i = 0; i < m.rows(); ++i)
    for (Eigen::Index j = 0; j < m.cols(); ++j) t[i][j] = static_cast<float>(m(i, j));
  return t;
}

torch::jit::Module script_module(Net& net, const NetworkOptions& o, const Eigen::VectorXd& in_mean,
                                 const Eigen::VectorXd& in_scale, const Eigen::VectorXd& out_mean,
                                 const Eigen::VectorXd& out_scale, const LinearSkip& skip) {
  torch::jit::Module m("ThermotwinCnnBiGruAttention");
  const auto param = [&](const std::string& name, const torch::Tensor& t) {
    m.register_parameter(name, t.detach().clone(), false);
  };
  m.register_buffer("in_mean", float_tensor(in_mean));
  m.register_buffer("in_scale", float_tensor(in_scale));
  m.register_buffer("out_mean", float_tensor(out_mean));
  m.register_buffer("out_scale", float_tensor(out_scale));
  m.register_buffer("skip_w", float_tensor(skip.weights));
  m.register_buffer("skip_b", float_tensor(skip.intercept));
  m.register_attribute("window_steps", c10::IntType::get(), o.window_steps);
  m.register_attribute("window_stride", c10::IntType::get(), o.window_stride);
  m.register_attribute("sample_interval_s", c10::FloatType::get(), o.sample_interval_s);
  param("conv1_w", net->conv1->weight);
  param("conv1_b", net->conv1->bias);
  param("conv2_w", net->conv2->weight);
  param("conv2_b", net->conv2->bias);
  param("norm_w", net->norm->weight);
  param("norm_b", net->norm->bias);
  m.register_buffer("norm_mean", net->norm->running_mean.detach().clone());
  m.register_buffer("norm_var", net->norm->running_var.detach().clone());
  const std::vector<torch::Tensor> gru = net->gru->all_weights();
  for (std::size_t i = 0; i < gru.size(); ++i) param("gru_" + std::to_string(i), gru[i]);
  param("key_w", net->key->weight);
  param("key_b", net->key->bias);
  param("head_w", net->head->weight);
  param("head_b", net->head->bias);
  m.define(script_source(o, static_cast<int>(gru.size())));
  m.eval();
  return m;
}

/// Standard deviation, or 1 for a constant column so that it standardises to zeros.
Eigen::VectorXd column_scale(const Eigen::MatrixXd& rows, const Eigen::VectorXd& mean) {
  Eigen::VectorXd scale(rows.cols());
  for (Eigen::Index c = 0; c < rows.cols(); ++c) {
    const double sd = std::sqrt((rows.col(c).array() - mean(c)).square().mean());
    scale(c) = sd > 1e-12 * std::max(1.0, std::abs(mean(c))) ? sd : 1.0;
  }
  return scale;
}

Eigen::MatrixXd stacked(const std::vector<Eigen::MatrixXd>& parts) {
  Eigen::Index rows = 0;
  for (const auto& p : parts) rows += p.rows();
  Eigen::MatrixXd out(rows, parts.front().cols());
  Eigen::Index r = 0;
  for (const auto& p : parts) {
    out.middleRows(r, p.rows()) = p;
    r += p.rows();
  }
  return out;
}

/// Windows (steps x #inputs) ending at every train_every-th row of [begin, end) of one group,
/// appended to `x`, and the outputs at those rows appended to `y`; all standardised, float.
void append_windows(const Eigen::MatrixXd& inputs, const Eigen::MatrixXd& outputs,
                    Eigen::Index begin, Eigen::Index end, const NetworkOptions& o,
                    const Eigen::VectorXd& in_mean, const Eigen::VectorXd& in_scale,
                    const Eigen::VectorXd& out_mean, const Eigen::VectorXd& out_scale,
                    std::vector<float>& x, std::vector<float>& y) {
  const int every = o.train_every > 0 ? o.train_every : o.window_stride;
  for (Eigen::Index i = begin; i < end; i += every) {
    for (int j = 0; j < o.window_steps; ++j) {
      const Eigen::Index r = std::max<Eigen::Index>(
          0, i - static_cast<Eigen::Index>(o.window_steps - 1 - j) * o.window_stride);
      for (Eigen::Index c = 0; c < inputs.cols(); ++c)
        x.push_back(static_cast<float>((inputs(r, c) - in_mean(c)) / in_scale(c)));
    }
    for (Eigen::Index c = 0; c < outputs.cols(); ++c)
      y.push_back(static_cast<float>((outputs(i, c) - out_mean(c)) / out_scale(c)));
  }
}

torch::Tensor tensor_of(std::vector<float>& values, std::vector<int64_t> shape) {
  return torch::from_blob(values.data(), shape, torch::kFloat32).clone();
}

void require_sequences(const Sequences& s, const std::string& what, int inputs, int outputs) {
  if (s.inputs.size() != s.outputs.size())
    throw core::DataError(what + ": " + std::to_string(s.inputs.size()) + " input and " +
                          std::to_string(s.outputs.size()) +
                          " output sequences; expected one of each per group");
  for (std::size_t g = 0; g < s.inputs.size(); ++g) {
    const auto& x = s.inputs[g];
    const auto& y = s.outputs[g];
    if (x.rows() != y.rows() || x.rows() < 1 || x.cols() != inputs || y.cols() != outputs)
      throw core::DataError(what + " group " + std::to_string(g) + ": " + std::to_string(x.rows()) +
                            "x" + std::to_string(x.cols()) + " inputs and " +
                            std::to_string(y.rows()) + "x" + std::to_string(y.cols()) +
                            " outputs; expected the same rows, " + std::to_string(inputs) +
                            " input and " + std::to_string(outputs) + " output columns");
    if (!x.allFinite() || !y.allFinite())
      throw core::DataError(what + " group " + std::to_string(g) +
                            ": a non-finite value; hint: drop incomplete rows first");
  }
}

void require_options(const NetworkOptions& o) {
  const auto bad = [](const std::string& key, double v, const std::string& expected) {
    throw core::DataError("network option " + key + " = " + std::to_string(v) + ": expected " +
                          expected);
  };
  if (o.window_steps < 2) bad("window_steps", o.window_steps, ">= 2 (pooling halves it)");
  if (o.window_stride < 1) bad("window_stride", o.window_stride, ">= 1");
  if (o.train_every < 0) bad("train_every", o.train_every, ">= 0 (0: window_stride)");
  if (o.conv_channels < 1) bad("conv_channels", o.conv_channels, ">= 1");
  if (o.kernel_size < 1 || o.kernel_size % 2 == 0) bad("kernel_size", o.kernel_size, "odd, >= 1");
  if (o.gru_hidden < 1) bad("gru_hidden", o.gru_hidden, ">= 1");
  if (o.gru_layers < 1) bad("gru_layers", o.gru_layers, ">= 1");
  if (o.max_epochs < 1) bad("max_epochs", o.max_epochs, ">= 1");
  if (o.patience < 1) bad("patience", o.patience, ">= 1");
  if (o.batch_size < 1) bad("batch_size", o.batch_size, ">= 1");
  if (!(o.learning_rate > 0.0)) bad("learning_rate", o.learning_rate, "> 0");
  if (!(o.weight_decay >= 0.0)) bad("weight_decay", o.weight_decay, ">= 0");
  if (!(o.time_budget_s > 0.0)) bad("time_budget_s", o.time_budget_s, "> 0");
  if (o.threads < 1) bad("threads", o.threads, ">= 1");
}

/// Weights drawn from the network's own generator (never torch's global one), so that training
/// is reproducible and independent of other torch users: uniform ±1/sqrt(fan-in) for weights,
/// zero biases, unit normalisation gains.
void initialise(Net& net, at::Generator& gen, int gru_hidden) {
  torch::NoGradGuard no_grad;
  for (auto& item : net->named_parameters()) {
    const std::string& name = item.key();
    torch::Tensor& p = item.value();
    if (name.rfind("norm.", 0) == 0) {
      if (name == "norm.weight")
        p.fill_(1.0);
      else
        p.zero_();
    } else if (name.find("bias") != std::string::npos) {
      p.zero_();
    } else {
      const double fan_in = name.rfind("gru.", 0) == 0
                                ? gru_hidden
                                : static_cast<double>(p.numel() / std::max<int64_t>(1, p.size(0)));
      const double bound = 1.0 / std::sqrt(fan_in);
      p.uniform_(-bound, bound, gen);
    }
  }
}

double mean_squared(Net& net, const torch::Tensor& x, const torch::Tensor& y) {
  torch::NoGradGuard no_grad;
  net->eval();
  double sum = 0.0;
  const int64_t n = x.size(0);
  for (int64_t b = 0; b < n; b += 4096) {
    const int64_t e = std::min(n, b + 4096);
    sum += (net->forward(x.slice(0, b, e)) - y.slice(0, b, e)).pow(2).sum().item<double>();
  }
  return sum / static_cast<double>(y.numel());
}

Eigen::MatrixXd run_script(torch::jit::Module module, std::vector<float>& windows, int64_t count,
                           int steps, int inputs) {
  torch::NoGradGuard no_grad;
  const torch::Tensor x = torch::from_blob(windows.data(), {count, steps, inputs}, torch::kFloat32);
  std::vector<torch::Tensor> parts;
  for (int64_t b = 0; b < count; b += 8192)
    parts.push_back(module.forward({x.slice(0, b, std::min(count, b + 8192))}).toTensor());
  const torch::Tensor y = torch::cat(parts, 0).to(torch::kFloat64).contiguous();
  Eigen::MatrixXd out(y.size(0), y.size(1));
  const double* data = y.data_ptr<double>();
  for (int64_t i = 0; i < y.size(0); ++i)
    for (int64_t c = 0; c < y.size(1); ++c) out(i, c) = data[i * y.size(1) + c];
  return out;
}

std::vector<float> raw_windows(const std::vector<Eigen::MatrixXd>& windows) {
  std::vector<float> out;
  for (const auto& w : windows)
    for (Eigen::Index r = 0; r < w.rows(); ++r)
      for (Eigen::Index c = 0; c < w.cols(); ++c) out.push_back(static_cast<float>(w(r, c)));
  return out;
}

}  // namespace

/// A network the engine made: the TorchScript is its one inference path, in memory and on file.
struct TorchNetwork final : Network::Impl {
  torch::jit::Module script;

  Eigen::MatrixXd prediction(const Eigen::MatrixXd& inputs) const override;
  Eigen::VectorXd window_prediction(const Eigen::MatrixXd& window) const override;
  void save_torchscript(const std::filesystem::path& file) const override;
};

Eigen::MatrixXd TorchNetwork::prediction(const Eigen::MatrixXd& inputs) const {
  const TorchNetwork& n = *this;
  if (inputs.cols() != n.inputs || !inputs.allFinite())
    throw core::DataError("network prediction on " + std::to_string(inputs.cols()) +
                          " input columns (or a non-finite value); expected " +
                          std::to_string(n.inputs) + " finite columns");
  if (inputs.rows() == 0) return Eigen::MatrixXd(0, n.outputs);
  std::vector<Eigen::Index> rows(static_cast<std::size_t>(inputs.rows()));
  for (Eigen::Index i = 0; i < inputs.rows(); ++i) rows[static_cast<std::size_t>(i)] = i;
  std::vector<float> x =
      raw_windows(windows_at(inputs, n.options.window_steps, n.options.window_stride, rows));
  TorchThreads threads(n.options.threads);
  return run_script(n.script, x, inputs.rows(), n.options.window_steps, n.inputs);
}

Eigen::VectorXd TorchNetwork::window_prediction(const Eigen::MatrixXd& window) const {
  const TorchNetwork& n = *this;
  if (window.rows() != n.options.window_steps || window.cols() != n.inputs)
    throw core::DataError("network window of " + std::to_string(window.rows()) + "x" +
                          std::to_string(window.cols()) + "; expected " +
                          std::to_string(n.options.window_steps) + "x" + std::to_string(n.inputs));
  std::vector<float> x = raw_windows({window});
  TorchThreads threads(n.options.threads);
  return run_script(n.script, x, 1, n.options.window_steps, n.inputs).row(0).transpose();
}

void TorchNetwork::save_torchscript(const std::filesystem::path& file) const {
  const std::filesystem::path part = file.string() + ".part";
  try {
    TorchThreads threads(options.threads);
    script.save(part.string());
  } catch (const c10::Error& e) {
    std::filesystem::remove(part);
    throw core::DataError(file.string() +
                          ": cannot write the TorchScript network: " + e.what_without_backtrace());
  }
  std::filesystem::rename(part, file);
}

namespace {

void require_skip(const LinearSkip& skip, int inputs, int outputs) {
  if (skip.intercept.size() != outputs || skip.weights.rows() != outputs ||
      skip.weights.cols() != inputs || !skip.intercept.allFinite() || !skip.weights.allFinite())
    throw core::DataError("network linear skip of " + std::to_string(skip.intercept.size()) +
                          " intercepts and " + std::to_string(skip.weights.rows()) + "x" +
                          std::to_string(skip.weights.cols()) + " weights; expected " +
                          std::to_string(outputs) + " and " + std::to_string(outputs) + "x" +
                          std::to_string(inputs) + ", finite");
}

/// The sequences with the skip's prediction taken from the outputs: what the network learns.
Sequences residual(const Sequences& s, const LinearSkip& skip) {
  Sequences out = s;
  for (std::size_t g = 0; g < out.outputs.size(); ++g)
    out.outputs[g] = (s.outputs[g] - s.inputs[g] * skip.weights.transpose()).rowwise() -
                     skip.intercept.transpose();
  return out;
}

/// The standardisation (x - mean) / scale of the fitting rows, into n.in_mean ... n.out_scale.
void set_standardisation(Network::Impl& n, const Sequences& fit) {
  const Eigen::MatrixXd x_all = stacked(fit.inputs), y_all = stacked(fit.outputs);
  n.in_mean = x_all.colwise().mean().transpose();
  n.in_scale = column_scale(x_all, n.in_mean);
  // With a skip the outputs are its residuals, centred by its intercept over every given row:
  // no mean is added, so that the untrained network (its last layer zero) is the skip exactly.
  n.out_mean = n.skip ? Eigen::VectorXd::Zero(n.outputs).eval()
                      : Eigen::VectorXd(y_all.colwise().mean().transpose());
  n.out_scale = column_scale(y_all, n.out_mean);
  if (n.options.common_output_scale)
    n.out_scale.setConstant(
        std::sqrt(n.out_scale.squaredNorm() / static_cast<double>(n.out_scale.size())));
}

/// Standardised float windows, flattened: fitting inputs and outputs, validation likewise.
struct Windows {
  std::vector<float> xf, yf, xv, yv;
};

/// Windows: every row of the fitting groups; the validation groups', or the last fifth of each
/// fitting group's rows when there are none.
Windows training_windows(const Network::Impl& n, const Sequences& fit,
                         const Sequences& validation) {
  Windows w;
  const auto add = [&](const Eigen::MatrixXd& x, const Eigen::MatrixXd& y, Eigen::Index b,
                       Eigen::Index e, std::vector<float>& xs, std::vector<float>& ys) {
    append_windows(x, y, b, e, n.options, n.in_mean, n.in_scale, n.out_mean, n.out_scale, xs, ys);
  };
  for (std::size_t g = 0; g < fit.inputs.size(); ++g) {
    const Eigen::Index rows = fit.inputs[g].rows();
    const Eigen::Index cut = validation.inputs.empty() ? rows - rows / 5 : rows;
    add(fit.inputs[g], fit.outputs[g], 0, cut, w.xf, w.yf);
    add(fit.inputs[g], fit.outputs[g], cut, rows, w.xv, w.yv);
  }
  for (std::size_t g = 0; g < validation.inputs.size(); ++g)
    add(validation.inputs[g], validation.outputs[g], 0, validation.inputs[g].rows(), w.xv, w.yv);
  return w;
}

/// Adam, or AdamW when there is weight decay.
std::unique_ptr<torch::optim::Optimizer> optimiser(Net& net, const NetworkOptions& o) {
  if (o.weight_decay > 0.0)
    return std::make_unique<torch::optim::AdamW>(
        net->parameters(),
        torch::optim::AdamWOptions(o.learning_rate).weight_decay(o.weight_decay));
  return std::make_unique<torch::optim::Adam>(net->parameters(),
                                              torch::optim::AdamOptions(o.learning_rate));
}

/// The parameters then the buffers of the epoch with the lowest finite validation loss (none
/// when no epoch had one), and that loss.
struct BestWeights {
  std::vector<torch::Tensor> tensors;
  double loss = std::numeric_limits<double>::infinity();
};

/// Epochs of shuffled mini-batches (the order drawn from `gen`), stopped after `patience` epochs
/// without a better validation loss or when the time budget since `start` is spent; records
/// epochs, best_epoch and budget_reached in `report`.
BestWeights best_weights(Net& net, at::Generator& gen, const torch::Tensor& x_fit,
                         const torch::Tensor& y_fit, const torch::Tensor& x_val,
                         const torch::Tensor& y_val, const NetworkOptions& o,
                         std::chrono::steady_clock::time_point start, TrainingReport& report) {
  const std::unique_ptr<torch::optim::Optimizer> adam = optimiser(net, o);
  const int64_t nf = x_fit.size(0);
  BestWeights best;
  const auto keep_if_best = [&](int epoch) {
    const double loss = mean_squared(net, x_val, y_val);
    if (!std::isfinite(loss) || loss >= best.loss) return;
    best.loss = loss;
    report.best_epoch = epoch;
    best.tensors.clear();
    for (const auto& p : net->parameters()) best.tensors.push_back(p.detach().clone());
    for (const auto& b : net->buffers()) best.tensors.push_back(b.detach().clone());
  };
  for (int epoch = 1; epoch <= o.max_epochs; ++epoch) {
    const torch::Tensor order = torch::randperm(nf, gen, torch::TensorOptions(torch::kLong));
    net->train();
    for (int64_t b = 0; b < nf; b += o.batch_size) {
      const torch::Tensor idx = order.slice(0, b, std::min(nf, b + o.batch_size));
      adam->zero_grad();
      const torch::Tensor loss =
          torch::mse_loss(net->forward(x_fit.index_select(0, idx)), y_fit.index_select(0, idx));
      loss.backward();
      adam->step();
    }
    report.epochs = epoch;
    keep_if_best(epoch);
    const double seconds =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    if (seconds > o.time_budget_s) {
      report.budget_reached = true;
      break;
    }
    if (epoch - report.best_epoch >= o.patience) break;
  }
  return best;
}

/// Puts the best weights back into `net`, or zeroes its last layer when the skip alone
/// (`skip_only`, its validation loss) does at least as well (best_epoch 0), and leaves it in
/// evaluation mode: the validation loss of the weights kept.
double restored_best(Net& net, const BestWeights& best, double skip_only, TrainingReport& report) {
  torch::NoGradGuard no_grad;
  auto params = net->parameters();
  const auto buffers = net->buffers();
  for (std::size_t i = 0; i < best.tensors.size() && i < params.size(); ++i)
    params[i].copy_(best.tensors[i]);
  for (std::size_t i = 0; i < best.tensors.size() && i < buffers.size(); ++i)
    buffers[i].copy_(best.tensors[params.size() + i]);
  double loss = best.loss;
  if (skip_only <= loss) {
    net->head->weight.zero_();
    net->head->bias.zero_();
    report.best_epoch = 0;
    loss = skip_only;
  }
  net->eval();
  return loss;
}

/// Every parameter of `net`, flattened in parameter order.
std::vector<float> flat_parameters(Net& net) {
  torch::NoGradGuard no_grad;
  std::vector<float> out;
  for (const auto& p : net->parameters()) {
    const torch::Tensor flat = p.detach().contiguous().view(-1);
    const float* d = flat.data_ptr<float>();
    out.insert(out.end(), d, d + flat.numel());
  }
  return out;
}

}  // namespace

// The engine's functions, which the loader calls through EngineFunctions (engine.hpp).
namespace engine {

Network trained_network(const Sequences& fit_given, const Sequences& validation_given,
                        const NetworkOptions& o, const std::optional<LinearSkip>& skip) {
  require_options(o);
  if (fit_given.inputs.empty())
    throw core::DataError("network training with no fitting group; expected at least one");
  const int inputs = static_cast<int>(fit_given.inputs.front().cols());
  const int outputs =
      static_cast<int>(fit_given.outputs.empty() ? 0 : fit_given.outputs.front().cols());
  if (inputs < 1 || outputs < 1)
    throw core::DataError("network training with " + std::to_string(inputs) + " inputs and " +
                          std::to_string(outputs) + " outputs; expected at least one of each");
  require_sequences(fit_given, "network fitting", inputs, outputs);
  require_sequences(validation_given, "network validation", inputs, outputs);
  if (skip) require_skip(*skip, inputs, outputs);
  const Sequences fit = skip ? residual(fit_given, *skip) : fit_given;
  const Sequences validation = skip ? residual(validation_given, *skip) : validation_given;

  auto impl = std::make_shared<TorchNetwork>();
  impl->options = o;
  impl->inputs = inputs;
  impl->outputs = outputs;
  impl->skip = skip;
  set_standardisation(*impl, fit);
  Windows w = training_windows(*impl, fit, validation);
  const int64_t nf = static_cast<int64_t>(w.yf.size()) / outputs;
  const int64_t nv = static_cast<int64_t>(w.yv.size()) / outputs;
  if (nf < 2 || nv < 1)
    throw core::DataError("network training on " + std::to_string(nf) + " fitting and " +
                          std::to_string(nv) +
                          " validation windows; expected at least 2 and 1; hint: give longer "
                          "groups");
  impl->report.training_windows = nf;
  impl->report.validation_windows = nv;

  const auto start = std::chrono::steady_clock::now();
  try {
    TorchThreads threads(o.threads);
    const torch::Tensor x_fit = tensor_of(w.xf, {nf, o.window_steps, inputs});
    const torch::Tensor y_fit = tensor_of(w.yf, {nf, outputs});
    const torch::Tensor x_val = tensor_of(w.xv, {nv, o.window_steps, inputs});
    const torch::Tensor y_val = tensor_of(w.yv, {nv, outputs});
    at::Generator gen = at::detail::createCPUGenerator(o.seed);
    Net net(inputs, outputs, o);
    initialise(net, gen, o.gru_hidden);
    const BestWeights best =
        best_weights(net, gen, x_fit, y_fit, x_val, y_val, o, start, impl->report);
    if (best.tensors.empty() && !skip)
      throw core::DataError(
          "network training gave no finite validation loss; hint: lower learning_rate");
    // With a skip, the linear model alone (the network's last layer zero, so that it adds
    // nothing) is a candidate of the early stopping too: epoch 0.
    const double skip_only =
        skip ? y_val.pow(2).mean().item<double>() : std::numeric_limits<double>::infinity();
    impl->report.validation_loss = restored_best(net, best, skip_only, impl->report);
    impl->weights = flat_parameters(net);
    impl->script = script_module(
        net, o, impl->in_mean, impl->in_scale, impl->out_mean, impl->out_scale,
        skip.value_or(LinearSkip{Eigen::VectorXd::Zero(outputs),
                                 Eigen::MatrixXd::Zero(outputs, inputs), Eigen::VectorXd()}));
  } catch (const c10::Error& e) {
    throw core::DataError(std::string("network training failed in libtorch: ") +
                          e.what_without_backtrace());
  }
  impl->report.seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return Network(impl);
}

namespace {

Eigen::VectorXd vector_of(const torch::Tensor& t) {
  const torch::Tensor d = t.to(torch::kFloat64).contiguous().view(-1);
  return Eigen::Map<const Eigen::VectorXd>(d.data_ptr<double>(), d.numel());
}

Eigen::MatrixXd matrix_of(const torch::Tensor& t) {
  const torch::Tensor d = t.to(torch::kFloat64).contiguous();
  using RowMajor = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;
  return Eigen::Map<const RowMajor>(d.data_ptr<double>(), d.size(0), d.size(1));
}

/// The shape, standardisation and skip a file written by save_torchscript holds, into `n`.
void read_script_buffers(TorchNetwork& n, const std::string& name) {
  const torch::jit::Module& m = n.script;
  for (const char* key : {"in_mean", "in_scale", "out_mean", "out_scale", "skip_w", "skip_b",
                          "window_steps", "window_stride"})
    if (!m.hasattr(key))
      throw core::DataError(name + ": a TorchScript module without '" + key +
                            "': not a network thermotwin wrote (save_torchscript)");
  n.options.window_steps = static_cast<int>(m.attr("window_steps").toInt());
  n.options.window_stride = static_cast<int>(m.attr("window_stride").toInt());
  // Files written before it was recorded: 0, not known.
  if (m.hasattr("sample_interval_s"))
    n.options.sample_interval_s = m.attr("sample_interval_s").toDouble();
  n.options.threads = 1;
  n.in_mean = vector_of(m.attr("in_mean").toTensor());
  n.in_scale = vector_of(m.attr("in_scale").toTensor());
  n.out_mean = vector_of(m.attr("out_mean").toTensor());
  n.out_scale = vector_of(m.attr("out_scale").toTensor());
  n.inputs = static_cast<int>(n.in_mean.size());
  n.outputs = static_cast<int>(n.out_mean.size());
  const torch::Tensor skip_w = m.attr("skip_w").toTensor();
  if (n.inputs < 1 || n.outputs < 1 || n.in_scale.size() != n.inputs ||
      n.out_scale.size() != n.outputs || skip_w.dim() != 2 || skip_w.size(0) != n.outputs ||
      skip_w.size(1) != n.inputs || n.options.window_steps < 1 || n.options.window_stride < 1)
    throw core::DataError(name + ": the network's buffers disagree on its shape (" +
                          std::to_string(n.inputs) + " inputs, " + std::to_string(n.outputs) +
                          " outputs, window " + std::to_string(n.options.window_steps) + ")");
  LinearSkip skip{vector_of(m.attr("skip_b").toTensor()), matrix_of(skip_w), Eigen::VectorXd()};
  // Zero buffers are the file's form of "no skip".
  if (skip.intercept.any() || skip.weights.any()) n.skip = std::move(skip);
  for (const auto& p : m.parameters()) {
    const torch::Tensor flat = p.detach().contiguous().view(-1);
    const float* d = flat.data_ptr<float>();
    n.weights.insert(n.weights.end(), d, d + flat.numel());
  }
}

}  // namespace

Network loaded_network(const std::filesystem::path& file) {
  if (!std::filesystem::is_regular_file(file))
    throw core::DataError(file.string() + ": no such network file");
  auto impl = std::make_shared<TorchNetwork>();
  TorchThreads threads(1);
  try {
    impl->script = torch::jit::load(file.string());
    impl->script.eval();
    read_script_buffers(*impl, file.string());
  } catch (const c10::Error& e) {
    throw core::DataError(file.string() + ": not a TorchScript network (" +
                          e.what_without_backtrace() + ")");
  }
  return Network(impl);
}

Eigen::MatrixXd torchscript_prediction(const std::filesystem::path& file,
                                       const std::vector<Eigen::MatrixXd>& windows) {
  if (windows.empty()) return Eigen::MatrixXd(0, 0);
  const Network network = loaded_network(file);
  Eigen::MatrixXd out(static_cast<Eigen::Index>(windows.size()), network.outputs());
  for (std::size_t k = 0; k < windows.size(); ++k)
    out.row(static_cast<Eigen::Index>(k)) = network.window_prediction(windows[k]).transpose();
  return out;
}

std::string parallel_info() {
  std::lock_guard<std::mutex> lock(torch_lock());
  return at::get_parallel_info();
}

}  // namespace engine

}  // namespace tt::torchnet

extern "C" __attribute__((visibility("default"))) const tt::torchnet::EngineFunctions*
tt_torchnet_engine() {
  namespace e = tt::torchnet::engine;
  static const tt::torchnet::EngineFunctions functions{
      tt::torchnet::engine_abi, &e::trained_network, &e::loaded_network, &e::torchscript_prediction,
      &e::parallel_info};
  return &functions;
}
