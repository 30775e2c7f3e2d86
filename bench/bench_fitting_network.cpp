// The CNN-BiGRU-attention network's cost on its own: training time and the time of one real-time
// prediction (one window), on synthetic sequences shaped like a measured run.
//
// Run:   bench_fitting_network [rows=8000] [inputs=4] [threads=1]
// Prints libtorch's threading backend, the training report (epochs, seconds) and the median,
// 10th and 90th percentile of 1000 one-window predictions [ms]. Target (issue 18): one
// prediction at most 1 ms on 2 cores.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <random>
#include <vector>

#include "fitting/torch/network.hpp"

int main(int argc, char** argv) {
  const int rows = argc > 1 ? std::atoi(argv[1]) : 8000;
  const int inputs = argc > 2 ? std::atoi(argv[2]) : 4;
  const int threads = argc > 3 ? std::atoi(argv[3]) : 1;
  // 1. Sequences: inputs are first-order responses to a random duty, the output a lagged mix.
  std::mt19937_64 gen(18);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  tt::torchnet::Sequences fit, validation;
  for (int g = 0; g < 3; ++g) {
    Eigen::MatrixXd x(rows / 3, inputs);
    Eigen::MatrixXd y(rows / 3, 1);
    double duty = 0.0, lag = 0.0;
    Eigen::VectorXd state = Eigen::VectorXd::Zero(inputs);
    for (int i = 0; i < x.rows(); ++i) {
      if (i % 200 == 0) duty = unit(gen);
      for (int k = 0; k < inputs; ++k) state(k) += (duty * (k + 1) - state(k)) / (20.0 + 30 * k);
      lag += (state.sum() - lag) / 60.0;
      x.row(i) = state.transpose();
      y(i, 0) = 1e-6 * lag;
    }
    (g < 2 ? fit : validation).inputs.push_back(x);
    (g < 2 ? fit : validation).outputs.push_back(y);
  }
  tt::torchnet::NetworkOptions o;
  o.window_steps = 16;
  o.window_stride = 16;
  o.max_epochs = 20;
  o.threads = threads;
  // 2. Training.
  const tt::torchnet::Network net = tt::torchnet::trained_network(fit, validation, o);
  std::printf("%s\n", tt::torchnet::parallel_info().c_str());
  std::printf("training: %ld windows, %d epochs, %.1f s (%d torch threads)\n",
              net.report().training_windows, net.report().epochs, net.report().seconds, threads);
  // 3. One-window predictions.
  const auto window =
      tt::torchnet::windows_at(fit.inputs[0], o.window_steps, o.window_stride, {rows / 3 - 1})
          .front();
  std::vector<double> ms;
  for (int k = 0; k < 1000; ++k) {
    const auto start = std::chrono::steady_clock::now();
    (void)net.window_prediction(window);
    ms.push_back(std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start)
                     .count());
  }
  std::sort(ms.begin(), ms.end());
  std::printf("one-window prediction: median %.3f ms, p10 %.3f ms, p90 %.3f ms\n", ms[500], ms[100],
              ms[900]);
  return 0;
}
