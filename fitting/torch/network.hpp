// The gantry patent's CNN-BiGRU-attention thermal-error network (seed 004), on libtorch, behind a
// plain C++ interface: nothing outside fitting/torch/ includes a torch header. libtorch lives in
// the engine, a module of its own (libthermotwin_torch.so, network.cpp) that the functions below
// load on their first call (engine_loader.cpp): a command that fits or runs no network does not
// pay libtorch's start, about a second of static initialisation.
// Structure: standardised input windows -> two 1-D convolutions (ReLU) -> max pooling by 2 ->
// batch normalisation -> two-layer bidirectional GRU -> dot-product attention over the feature
// dimension of the last GRU output -> one fully connected layer to every output at once; with a
// linear skip (LinearSkip), plus a fixed linear map of the window's last row, so that the network
// learns only what that linear model leaves.
// Trained on CPU with Adam (AdamW with weight decay) on the mean squared standardised error, early
// stopping on validation windows and a time budget. The same seed and thread count give the same
// weights.
#pragma once

#include <Eigen/Dense>
#include <algorithm>
#include <cstdint>
#include <filesystem>
#include <memory>
#include <optional>
#include <string>
#include <utility>
#include <vector>

namespace tt::torchnet {

struct NetworkOptions {
  /// entries of an input window, the last one the sample predicted
  int window_steps = 16;
  /// samples between two entries of a window
  int window_stride = 1;
  /// the median interval between the rows trained on [s] (0: not known): with window_stride, the
  /// time between two entries of a window, which a stream sampled at another rate needs
  double sample_interval_s = 0.0;
  /// training and early-stopping windows end every this many samples (0: window_stride):
  /// neighbouring windows of a finely sampled run are nearly the same, and training on each one
  /// costs time without adding information
  int train_every = 0;
  /// channels of both convolutions
  int conv_channels = 16;
  /// odd convolution kernel size
  int kernel_size = 3;
  /// GRU state size per direction
  int gru_hidden = 16;
  int gru_layers = 2;
  int max_epochs = 200;
  /// epochs without a better validation loss before training stops
  int patience = 25;
  int batch_size = 64;
  double learning_rate = 3e-3;
  /// decoupled weight decay (AdamW) per unit learning rate; 0: plain Adam. Shrinking the weights
  /// keeps the gates off saturation, so the network leaves its training range more gently
  double weight_decay = 0.0;
  /// one scale for every output (the root mean square of their standard deviations) instead of
  /// each its own: the loss then weighs outputs by their size, so a network for many outputs
  /// does not spend itself on those that are mostly noise
  bool common_output_scale = false;
  /// wall-clock limit of training [s]; reaching it ends training with the best weights so far
  /// (then the result depends on the machine's speed: the report says so)
  double time_budget_s = 300.0;
  std::uint64_t seed = 1;
  /// torch intra-op threads while training and predicting; 1 keeps the result independent of
  /// the caller's OpenMP team (inside a parallel region torch runs serially anyway)
  int threads = 1;
};

/// Sequences of several groups (runs): per group #samples x #inputs and #samples x #outputs,
/// rows equally spaced in time.
struct Sequences {
  std::vector<Eigen::MatrixXd> inputs;
  std::vector<Eigen::MatrixXd> outputs;
};

/// A linear model added to the network's output: output = intercept + weights · x_last + the
/// CNN-BiGRU-attention path, x_last the window's last row (the sample predicted) in the inputs'
/// units. It is fitted outside (by the caller, e.g. the ridge fit of the linear model chosen for
/// the target) and kept fixed: the network trains on what it leaves, and the linear model alone
/// (the last layer zeroed) is a candidate of the early stopping (reported as epoch 0), so a
/// network that does not improve on the linear model on the validation windows is that model.
struct LinearSkip {
  /// #outputs
  Eigen::VectorXd intercept;
  /// #outputs x #inputs
  Eigen::MatrixXd weights;
  /// #outputs ridge strengths they were fitted with (for reports; empty when not known)
  Eigen::VectorXd ridge_lambda;
};

struct TrainingReport {
  int epochs = 0;
  /// epoch (1-based) whose weights were kept; 0: the weights before training (with a linear
  /// skip, the linear model alone)
  int best_epoch = 0;
  /// mean squared standardised error on the validation windows at best_epoch
  double validation_loss = 0.0;
  double seconds = 0.0;
  bool budget_reached = false;
  long training_windows = 0;
  long validation_windows = 0;
};

/// A trained network; copies share the (immutable) weights.
class Network {
 public:
  struct Impl;
  explicit Network(std::shared_ptr<const Impl> impl) : impl_(std::move(impl)) {}

  /// #samples x #outputs: at each sample the prediction from the window ending there (entries
  /// before the first sample repeat the first row). inputs: #samples x #inputs.
  Eigen::MatrixXd prediction(const Eigen::MatrixXd& inputs) const;
  /// #outputs from one window, window_steps x #inputs: the real-time call.
  Eigen::VectorXd window_prediction(const Eigen::MatrixXd& window) const;
  /// The network as TorchScript, with the standardisation inside: forward(x) takes a float32
  /// batch x window_steps x #inputs tensor in the training inputs' units and returns batch x
  /// #outputs in the outputs' units (the linear skip included: buffers skip_w, skip_b, zero
  /// without one); attributes window_steps, window_stride and sample_interval_s. Written to a
  /// temporary name and renamed.
  void save_torchscript(const std::filesystem::path& file) const;

  int inputs() const;
  int outputs() const;
  const NetworkOptions& options() const;
  const TrainingReport& report() const;
  /// #inputs mean and scale of the standardisation (x - mean) / scale, and #outputs likewise.
  Eigen::VectorXd input_mean() const;
  Eigen::VectorXd input_scale() const;
  Eigen::VectorXd output_mean() const;
  Eigen::VectorXd output_scale() const;
  /// the fixed linear part, when the network was trained with one
  const std::optional<LinearSkip>& linear_skip() const;
  /// Every weight in a fixed order: for comparing two trainings.
  std::vector<float> flat_weights() const;

 private:
  std::shared_ptr<const Impl> impl_;
};

/// What a network is: its shape, standardisation and weights here, its TorchScript in the engine,
/// which runs it through the three calls below. Only the engine makes one.
struct Network::Impl {
  NetworkOptions options;
  TrainingReport report;
  int inputs = 0, outputs = 0;
  Eigen::VectorXd in_mean, in_scale, out_mean, out_scale;
  std::optional<LinearSkip> skip;
  std::vector<float> weights;

  virtual ~Impl() = default;
  virtual Eigen::MatrixXd prediction(const Eigen::MatrixXd& inputs) const = 0;
  virtual Eigen::VectorXd window_prediction(const Eigen::MatrixXd& window) const = 0;
  virtual void save_torchscript(const std::filesystem::path& file) const = 0;
};

inline Eigen::MatrixXd Network::prediction(const Eigen::MatrixXd& inputs) const {
  return impl_->prediction(inputs);
}
inline Eigen::VectorXd Network::window_prediction(const Eigen::MatrixXd& window) const {
  return impl_->window_prediction(window);
}
inline void Network::save_torchscript(const std::filesystem::path& file) const {
  impl_->save_torchscript(file);
}
inline int Network::inputs() const {
  return impl_->inputs;
}
inline int Network::outputs() const {
  return impl_->outputs;
}
inline const NetworkOptions& Network::options() const {
  return impl_->options;
}
inline const TrainingReport& Network::report() const {
  return impl_->report;
}
inline Eigen::VectorXd Network::input_mean() const {
  return impl_->in_mean;
}
inline Eigen::VectorXd Network::input_scale() const {
  return impl_->in_scale;
}
inline Eigen::VectorXd Network::output_mean() const {
  return impl_->out_mean;
}
inline Eigen::VectorXd Network::output_scale() const {
  return impl_->out_scale;
}
inline const std::optional<LinearSkip>& Network::linear_skip() const {
  return impl_->skip;
}
inline std::vector<float> Network::flat_weights() const {
  return impl_->weights;
}

/// Trains on the windows of `fit` and stops early on those of `validation`; with no validation
/// sequences the last fifth of each fitting group's windows validates (and is not trained on).
/// With a skip the network learns the outputs minus the skip's prediction (standardised on the
/// fitting rows); the skip is part of the model, in memory and in the TorchScript file.
/// Throws core::DataError on inconsistent sizes, non-finite values or too few windows.
Network trained_network(const Sequences& fit, const Sequences& validation,
                        const NetworkOptions& options,
                        const std::optional<LinearSkip>& skip = std::nullopt);

/// A network read back from a file written by save_torchscript (torch::jit::load): its window
/// shape, standardisation and linear skip from the file's attributes and buffers, its predictions
/// those of the network that was saved. Options other than window_steps, window_stride and
/// sample_interval_s (0 in a file written before it was recorded) are defaults (threads 1); the
/// training report is empty. Throws core::DataError naming the file when
/// it is missing or not such a network.
Network loaded_network(const std::filesystem::path& file);

/// Loads a file written by save_torchscript and runs it on windows (each window_steps x #inputs):
/// #windows x #outputs. What another program does with the file.
Eigen::MatrixXd torchscript_prediction(const std::filesystem::path& file,
                                       const std::vector<Eigen::MatrixXd>& windows);

/// The window ending at each of the rows `rows` of `inputs` (window_steps x #inputs each).
inline std::vector<Eigen::MatrixXd> windows_at(const Eigen::MatrixXd& inputs, int steps, int stride,
                                               const std::vector<Eigen::Index>& rows) {
  std::vector<Eigen::MatrixXd> out;
  out.reserve(rows.size());
  for (Eigen::Index i : rows) {
    Eigen::MatrixXd w(steps, inputs.cols());
    for (int j = 0; j < steps; ++j)
      w.row(j) = inputs.row(
          std::max<Eigen::Index>(0, i - static_cast<Eigen::Index>(steps - 1 - j) * stride));
    out.push_back(std::move(w));
  }
  return out;
}

/// libtorch's report of its threading backend and thread counts, for benchmark records.
std::string parallel_info();

}  // namespace tt::torchnet
