// thermotwin compensate: live compensation from a fitted model, or from a reduced model through
// the physics observer. Reads sensor samples as they arrive and writes, per sample, the predicted
// thermal drift of every target with its uncertainty and a status.
//   thermotwin compensate (--model FIT.json [--network-every-s S]
//                          | --rom DIR [--case CASE] [--filter-every-s S] [observer options])
//                         [--in FILE [--until-eof | --idle-s S]] [--out FILE] [--flush]
//                         [--poll-ms MS] [--max-behind-mib M] [--column MODEL=STREAM ...]
// Input: CSV lines in the measured-data format (docs/measured-data.md): a header time_s,<ids...>,
// then one sample per line; on standard input (to its end) or from FILE, followed as it grows.
// Output (stdout or FILE): time_s, <target>_predicted_um, <target>_sigma_um per target, status.
// See docs/compensate.md for the statuses, the stop conditions and what is not covered.
// 1. The model: the chosen model of each target from fit.json (io::read_deployed_models, a
//    network from its TorchScript file beside it), or the reduced model checked against its case
//    and mesh (as observe does).
// 2. The stream's header bound to the model by name (fitting::Compensator, or
//    solvers::LiveObserver on the sensors and speed_rpm): a column the model reads that the header
//    lacks refuses the stream, naming it; --column reads a stream's column under the model's name.
// 3. Sample by sample: parse, step the model (the observer once per filter period, a network
//    once per --network-every-s), write one
//    line; output is buffered and written when the input pauses, per line with --flush or on a
//    terminal, never waiting for its reader: lines beyond --max-behind-mib are dropped, and the
//    next line's status says how many.
#include <unistd.h>

#include <algorithm>
#include <csignal>
#include <functional>
#include <limits>
#include <memory>

#include "app/commands.hpp"
#include "app/observer_options.hpp"
#include "core/errors.hpp"
#include "core/text.hpp"
#include "core/units.hpp"
#include "fitting/compensation.hpp"
#include "io/case_reader.hpp"
#include "io/fit_model_in.hpp"
#include "io/reduced_model_io.hpp"
#include "io/sample_stream.hpp"
#include "io/sigma_calibration_io.hpp"
#include "mesh/mesher.hpp"
#include "solvers/observer_live.hpp"
#include "studies/observe_run.hpp"

namespace tt::app {
namespace {

volatile std::sig_atomic_t stop_requested = 0;

extern "C" void request_stop(int) {
  stop_requested = 1;
}

/// Ctrl-C, SIGTERM and SIGHUP end the stream after the current line, with every line written.
/// No SA_RESTART: a blocking read returns, so the reader sees the request at once.
void stop_on_signals() {
  for (const int sig : {SIGINT, SIGTERM, SIGHUP}) {
    struct sigaction on {};
    on.sa_handler = request_stop;
    sigemptyset(&on.sa_mask);
    ::sigaction(sig, &on, nullptr);
  }
}

/// A model bound to a stream's columns: its targets, and its answer to each sample.
struct BoundModel {
  std::vector<std::string> targets;
  std::function<const core::LiveStep&(double, const Eigen::VectorXd&)> next;
};

/// A model that binds itself to the stream's columns when its header arrives.
using Binder = std::function<BoundModel(const std::vector<std::string>&)>;

/// fit.json's chosen models.
Binder fitted_model(const std::filesystem::path& path, double network_every_s) {
  const std::vector<io::DeployedModel> deployed = io::read_deployed_models(path);
  std::vector<fitting::FittedModel> models;
  std::vector<std::string> targets;
  Eigen::VectorXd sigma(static_cast<Eigen::Index>(deployed.size()));
  for (std::size_t t = 0; t < deployed.size(); ++t) {
    models.push_back(deployed[t].model);
    targets.push_back(deployed[t].model.target_name);
    sigma(static_cast<Eigen::Index>(t)) = deployed[t].uncertainty;
  }
  return [models, targets, sigma, network_every_s](const std::vector<std::string>& columns) {
    auto compensator =
        std::make_shared<fitting::Compensator>(models, columns, sigma, network_every_s);
    const auto next = [compensator](double t, const Eigen::VectorXd& v) -> const core::LiveStep& {
      return compensator->next(t, v);
    };
    return BoundModel{targets, next};
  };
}

/// The reduced model and the case it was built from (--case, or the one it records), checked
/// against each other; `mesh` gets the case's mesh.
std::shared_ptr<const io::ReducedModelFile> reduced_model(
    const CompensateArgs& args, std::shared_ptr<core::CaseSpec>& spec,
    std::shared_ptr<const mesh::TetMesh>& mesh) {
  auto rom = std::make_shared<io::ReducedModelFile>(io::read_reduced_model(args.rom));
  const std::filesystem::path case_file =
      args.case_file.empty() ? std::filesystem::path(rom->case_file) : args.case_file;
  if (!std::filesystem::exists(case_file))
    throw core::DataError((args.rom / "reduced_model.json").string() +
                          ": the case it was built from, " + case_file.string() +
                          ", is not there; give it with --case");
  spec = std::make_shared<core::CaseSpec>(io::read_case(case_file));
  mesh = std::make_shared<const mesh::TetMesh>(mesh::mesh_case(*spec));
  io::check_reduced_model_fits(*rom, io::reduced_model_key(*spec, *mesh), args.rom);
  if (args.initial_temperature_c) spec->thermal.initial_temperature_c = *args.initial_temperature_c;
  return rom;
}

/// The physics observer on the reduced model, on its sensors: --sensors, or every column the
/// model can read (located by --meta, or a named point of the model).
Binder observed_model(const CompensateArgs& args) {
  std::shared_ptr<core::CaseSpec> spec;
  std::shared_ptr<const mesh::TetMesh> mesh;
  const auto rom = reduced_model(args, spec, mesh);
  auto meta = std::make_shared<io::MeasuredRun>();
  if (!args.meta.empty()) {
    *meta = io::read_measured_meta(args.meta);
    if (meta->initial_temperature_c && !args.initial_temperature_c)
      spec->thermal.initial_temperature_c = *meta->initial_temperature_c;
  } else {
    mesh.reset();  // no positions: every sensor at its named point
  }
  const ObserverOptions options = args.observer;
  // A malformed --sigma-calibration is the file's fault, not the header's: read once, before the
  // stream.
  std::shared_ptr<const io::SigmaCalibrationFile> calibration;
  if (!options.sigma_calibration.empty())
    calibration = std::make_shared<const io::SigmaCalibrationFile>(
        io::read_sigma_calibration(options.sigma_calibration));
  const std::string source = args.meta.empty() ? "the stream" : args.meta.string();
  const solvers::LiveOptions live{.drift_every_s = options.drift_readings_every_s,
                                  .filter_every_s = args.filter_every_s,
                                  .from_first_sample = args.from_first_sample};
  return [rom, spec, mesh, meta, options, calibration, source,
          live](const std::vector<std::string>& columns) {
    std::vector<std::string> sensors = options.sensors;
    if (sensors.empty())
      sensors = studies::readable_sensors(rom->twin.outputs, mesh.get(), meta->sensors, columns,
                                          meta->ambient_sensor);
    if (sensors.empty())
      throw core::DataError(
          "no column is located by --meta or a named point of the reduced model; name the "
          "sensors with --sensors");
    const studies::SensorReadout readout =
        studies::sensor_readout(rom->twin, mesh.get(), meta->sensors, sensors, source);
    const solvers::ObserverSetup setup =
        observer_setup(options, rom->twin, *spec, sensors, readout.rows, calibration.get());
    auto observer = std::make_shared<solvers::LiveObserver>(rom->twin.model.system, *spec, setup,
                                                            sensors, columns, "speed_rpm", live);
    // The stream's temperatures are in degC and its drifts in um (the measured-data format), the
    // observer's in K and m. The observer refers to the system and the case: they live as long
    // as it.
    auto si = std::make_shared<Eigen::VectorXd>();
    const bool from_first = live.from_first_sample;
    const auto next = [observer, rom, spec, si, from_first](
                          double t, const Eigen::VectorXd& v) -> const core::LiveStep& {
      *si = v;
      for (int c : observer->sensor_columns()) (*si)(c) += core::kCelsiusOffset;
      for (int c : observer->drift_columns())
        if (c >= 0) (*si)(c) *= 1e-6;
      try {
        return observer->next(t, *si);
      } catch (const core::DataError& e) {  // a first sample on a clock's time
        throw core::DataError(std::string(e.what()) +
                              (from_first ? "" : " (--time-from-first-sample)"));
      }
    };
    return BoundModel{setup.target_names, next};
  };
}

/// --column MODEL=STREAM, each as (the model's name, the stream's column). Throws DataError
/// naming a value that is not of that form.
std::vector<std::pair<std::string, std::string>> column_aliases(
    const std::vector<std::string>& given) {
  std::vector<std::pair<std::string, std::string>> aliases;
  for (const std::string& a : given) {
    const std::size_t eq = a.find('=');
    if (eq == std::string::npos || eq == 0 || eq + 1 == a.size() || a.find('=', eq + 1) != a.npos)
      throw core::DataError("compensate: --column '" + a +
                            "': expected MODEL=STREAM, the name the model reads and the stream's "
                            "column, e.g. speed_rpm=spindle_rpm");
    aliases.emplace_back(a.substr(0, eq), a.substr(eq + 1));
  }
  return aliases;
}

/// The stream's columns as the model reads them: each aliased column renamed. Throws DataError
/// naming the stream when an alias's column is not in it, or its name already is.
std::vector<std::string> model_columns(
    std::vector<std::string> columns,
    const std::vector<std::pair<std::string, std::string>>& aliases, const std::string& in_name) {
  const std::vector<std::string> stream = columns;
  for (const auto& [name, column] : aliases) {
    const auto it = std::find(stream.begin(), stream.end(), column);
    if (it == stream.end())
      throw core::DataError(in_name + ": --column " + name + "=" + column +
                            ": the stream has no column '" + column + "'; it has " +
                            core::joined(stream));
    if (std::find(stream.begin(), stream.end(), name) != stream.end())
      throw core::DataError(in_name + ": --column " + name + "=" + column +
                            ": the stream has a column '" + name +
                            "' already; read one of the two");
    columns[static_cast<std::size_t>(it - stream.begin())] = name;
  }
  return columns;
}

/// The stream's header read and the model bound to its columns, read as `aliases` say;
/// `columns` gets the stream's own names.
BoundModel bound_to_header(const Binder& bind, io::LineReader& reader, const std::string& in_name,
                           const std::vector<std::pair<std::string, std::string>>& aliases,
                           std::vector<std::string>& columns) {
  std::string_view line;
  if (!reader.next(line, {}))
    throw core::DataError(in_name + ": no header line; expected time_s and the sensor ids");
  columns = io::stream_columns(line, in_name);
  const std::vector<std::string> read_as = model_columns(columns, aliases, in_name);
  try {
    return bind(read_as);
  } catch (const core::DataError& e) {
    throw core::DataError(in_name + ": header refused: " + e.what());
  }
}

/// Sample by sample: parse, step the model, write one line (a torn or foreign line is skipped,
/// the last prediction repeated). The output is written when the input pauses, per line, or when
/// 64 KiB are held, as far as its reader takes it without waiting; lines its reader has fallen
/// behind on are dropped, and the next line says how many.
void predictions(io::LineReader& reader, const std::string& in_name, const BoundModel& model,
                 const std::vector<std::string>& columns, io::BufferedWriter& output,
                 bool per_line) {
  Eigen::VectorXd values(static_cast<Eigen::Index>(columns.size()));
  Eigen::VectorXd last = Eigen::VectorXd::Constant(static_cast<Eigen::Index>(model.targets.size()),
                                                   std::numeric_limits<double>::quiet_NaN());
  Eigen::VectorXd last_sigma = last;
  const auto write_held = [&] { return output.write_ready(); };
  std::string_view line;
  for (long long number = 2; reader.next(line, write_held); ++number) {
    if (line.empty()) continue;
    double time = 0.0;
    std::string status = "malformed";
    if (io::parsed_sample(line, time, values)) {
      const core::LiveStep& step = [&]() -> const core::LiveStep& {
        try {
          return model.next(time, values);
        } catch (const core::DataError& e) {
          throw core::DataError(in_name + ": line " + std::to_string(number) + ": " + e.what());
        }
      }();
      if (step.status != core::SampleStatus::late) {
        last = step.predicted;
        last_sigma = step.sigma;
      }
      status = io::status_text(step, columns);
    }
    if (const std::size_t dropped = output.drop_behind(); dropped > 0)
      status = io::with_dropped(status, dropped);
    io::append_output_line(output.text, time, last, last_sigma, status);
    if (per_line || output.held() >= (std::size_t(1) << 16)) output.write_ready();
  }
  output.flush();
}

}  // namespace

int compensate_command(const CompensateArgs& args) {
  // 1. The model, and the stream's columns it reads under other names.
  const auto aliases = column_aliases(args.columns);
  const Binder bind =
      args.rom.empty() ? fitted_model(args.model, args.network_every_s) : observed_model(args);
  // 2. The stream, its header bound to the model (the output is opened only then).
  const io::StreamFd in = io::StreamFd::reading(args.in);
  io::FollowOptions follow;
  follow.follow = !args.in.empty() && !args.until_eof;
  follow.idle_s = args.idle_s;
  follow.poll_ms = args.poll_ms;
  stop_on_signals();
  io::LineReader reader(in.fd(), in.name(), follow, &stop_requested);
  std::vector<std::string> columns;
  const BoundModel model = bound_to_header(bind, reader, in.name(), aliases, columns);
  const io::StreamFd out = io::StreamFd::writing(args.out);
  io::BufferedWriter output(out.fd(), out.name(),
                            static_cast<std::size_t>(args.max_behind_mib * (1 << 20)));
  output.text = io::output_header(model.targets);
  output.flush();
  // 3. Sample by sample.
  predictions(reader, in.name(), model, columns, output, args.flush || ::isatty(out.fd()));
  return 0;
}

}  // namespace tt::app
