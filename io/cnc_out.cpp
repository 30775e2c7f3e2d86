#include "io/cnc_out.hpp"

#include <cctype>
#include <cmath>
#include <cstdio>
#include <map>
#include <sstream>

#include "core/errors.hpp"
#include "core/units.hpp"

namespace tt::io {

using core::kMillimetresPerMetre;
using fitting::CncFormat;
using fitting::kCncFormatNames;

namespace {

constexpr const char* kAxisLetters[3] = {"X", "Y", "Z"};

std::string num(double v) {
  char buf[40];
  std::snprintf(buf, sizeof buf, "%.12g", v);
  return buf;
}

/// What a basis function (index >= 1) is: the increment of a sensor reading or an operating
/// input since the reference sample, possibly low-pass filtered (FeatureStream's order).
struct BasisTerm {
  std::string source;  /// sensor id or input name
  bool input = false;  /// an operating input (e.g. speed_rpm), not a temperature
  double tau = 0.0;    /// low-pass time constant [s]; 0: the increment itself
  std::string unit() const { return input ? "unit of " + source : "K"; }
};

std::vector<BasisTerm> basis_terms(const fitting::CncModel& m) {
  std::vector<BasisTerm> sources;
  for (const auto& s : m.features.sensor_names) sources.push_back({s, false, 0.0});
  for (const auto& s : m.features.input_names) sources.push_back({s, true, 0.0});
  std::vector<BasisTerm> terms = sources;
  for (double tau : m.features.time_constants)
    for (BasisTerm t : sources) {
      t.tau = tau;
      terms.push_back(t);
    }
  return terms;
}

/// The axes a law acts on: those whose model compensation is not identically zero.
std::vector<int> acting_directions(const fitting::CncModel& m) {
  std::vector<int> dirs;
  for (int d = 0; d < 3; ++d) {
    const auto di = static_cast<std::size_t>(d);
    if (m.tcp[di].cwiseAbs().maxCoeff() > 0.0 ||
        (m.axis[di].size() > 0 && m.axis[di].cwiseAbs().maxCoeff() > 0.0))
      dirs.push_back(d);
  }
  return dirs;
}

std::string header_lines(const std::string& comment, const std::string& title,
                         const std::string& source, const fitting::CncModel& m) {
  std::ostringstream o;
  o << comment << " thermotwin export: " << title << "\n"
    << comment << " from " << source << "; docs/cnc-export.md says how to install it.\n"
    << comment << " The compensation value is minus the model's predicted thermal error [mm].\n";
  if (!m.feed_axis.empty())
    o << comment << " Position: the " << m.feed_axis << " axis (" << kAxisLetters[m.feed_direction]
      << " direction), travel " << num(m.travel_min * kMillimetresPerMetre) << " .. "
      << num(m.travel_max * kMillimetresPerMetre) << " mm.\n";
  return o.str();
}

// ---- SINUMERIK 840D sl -----------------------------------------------------------------------

/// R-parameter numbers: readings from 100, reference readings from 200, PLC-formed basis values
/// (low-pass filtered increments) from 300.
/// In a synchronized action: an increment is (reading - reference), R100+k and R200+k for source
/// k (the unfiltered terms come first, one per source, in basis_terms' order); a filtered one is
/// R300+j, formed by the PLC.
std::string sinumerik_term(const std::vector<BasisTerm>& terms, std::size_t j) {
  if (terms[j].tau > 0.0) return "$R" + std::to_string(300 + j);
  return "($R" + std::to_string(100 + j) + "-$R" + std::to_string(200 + j) + ")";
}

std::string sinumerik_expression(const Eigen::VectorXd& c, const std::vector<BasisTerm>& terms,
                                 double factor) {
  std::string e = num(c(0) * factor);
  for (std::size_t j = 0; j < terms.size(); ++j) {
    const double v = c(static_cast<Eigen::Index>(j + 1)) * factor;
    if (v == 0.0) continue;
    e += (v < 0 ? "-" : "+") + num(std::abs(v)) + "*" + sinumerik_term(terms, j);
  }
  return e;
}

std::vector<CncFile> sinumerik_files(const fitting::CncModel& m, const fitting::LineLaw& law,
                                     const std::string& source) {
  const std::vector<BasisTerm> terms = basis_terms(m);
  std::ostringstream o;
  o << header_lines(";", "SINUMERIK 840D sl temperature compensation", source, m)
    << "; Law per axis: dK = $SA_TEMP_COMP_ABS_VALUE + (P - $SA_TEMP_COMP_REF_POSITION) *\n"
    << ";   $SA_TEMP_COMP_SLOPE, P the axis position (SD43900, SD43920, SD43910).\n"
    << "; Activation, machine data (then POWER ON):\n";
  const std::vector<int> dirs = acting_directions(m);
  for (int d : dirs) {
    const bool sloped = d == m.feed_direction && !m.feed_axis.empty() &&
                        law.slope[static_cast<std::size_t>(d)].cwiseAbs().maxCoeff() > 0.0;
    o << ";   MD32750 $MA_TEMP_COMP_TYPE[" << kAxisLetters[d] << "1] = " << (sloped ? 3 : 1)
      << (sloped ? "   ; bit 0 position-independent, bit 1 position-dependent\n"
                 : "   ; bit 0 position-independent\n");
  }
  o << ";   MD32760 $MA_COMP_ADD_VELO_FACTOR limits how fast a change is traversed and the slope.\n"
    << "; R-parameters the PLC writes (readings in degC, inputs in their unit):\n";
  for (std::size_t j = 0; j < terms.size(); ++j) {
    if (terms[j].tau > 0.0) {
      o << ";   R" << 300 + j << " = the increment of " << terms[j].source
        << " since its reference, low-pass filtered with tau = " << num(terms[j].tau)
        << " s (tau*y' + y = u), formed by the PLC\n";
    } else {
      o << ";   R" << 100 + j << " = reading of " << terms[j].source << ", R" << 200 + j
        << " = its reference (the reading at the state the model starts from)\n";
    }
  }
  o << "; Axis names X1, Y1, Z1: replace them with the machine axes of the X, Y and Z "
       "directions.\n\n";
  const double ref_mm = law.reference * kMillimetresPerMetre;
  for (int d : dirs)
    if (law.slope[static_cast<std::size_t>(d)].cwiseAbs().maxCoeff() > 0.0)
      o << "$SA_TEMP_COMP_REF_POSITION[" << kAxisLetters[d] << "1]=" << num(ref_mm) << "\n";
  o << "\n; Every interpolation cycle, modal and static (IDS) so it runs beside every program:\n";
  int id = 1;
  for (int d : dirs) {
    const auto di = static_cast<std::size_t>(d);
    o << "IDS=" << id++ << " WHENEVER TRUE DO $SA_TEMP_COMP_ABS_VALUE[" << kAxisLetters[d]
      << "1]=" << sinumerik_expression(law.value[di], terms, kMillimetresPerMetre) << "\n";
    if (law.slope[di].cwiseAbs().maxCoeff() > 0.0)
      o << "IDS=" << id++ << " WHENEVER TRUE DO $SA_TEMP_COMP_SLOPE[" << kAxisLetters[d]
        << "1]=" << sinumerik_expression(law.slope[di], terms, 1.0) << "\n";
  }
  o << "M17\n";
  return {{"THERMOTWIN_TEMP_COMP.SPF", o.str()}};
}

// ---- Tables: TwinCAT and Heidenhain ----------------------------------------------------------

/// CSV of a table law: position_mm, then per acting axis and basis function <axis>_<basis> [mm
/// per unit].
std::string table_csv(const fitting::CncModel& m, const fitting::TableLaw& t) {
  std::ostringstream o;
  o << "position_mm";
  const std::vector<int> dirs = acting_directions(m);
  for (int d : dirs)
    for (const auto& b : m.basis) o << "," << kAxisLetters[d] << "_mm_per[" << b << "]";
  o << "\n";
  for (Eigen::Index i = 0; i < t.positions.size(); ++i) {
    o << num(t.positions(i) * kMillimetresPerMetre);
    for (int d : dirs)
      for (Eigen::Index j = 0; j < static_cast<Eigen::Index>(m.basis.size()); ++j)
        o << "," << num(t.values[static_cast<std::size_t>(d)](i, j) * kMillimetresPerMetre);
    o << "\n";
  }
  return o.str();
}

std::string basis_list(const fitting::CncModel& m, const std::string& comment) {
  const std::vector<BasisTerm> terms = basis_terms(m);
  std::ostringstream o;
  o << comment << " Basis b[0..] (the PLC forms it; b[0] = 1):\n";
  o << comment << "   b[0] = 1\n";
  for (std::size_t j = 0; j < terms.size(); ++j) {
    o << comment << "   b[" << j + 1 << "] = " << m.basis[j + 1] << ": increment of "
      << terms[j].source << " since its reference reading [" << terms[j].unit() << "]";
    if (terms[j].tau > 0.0) o << ", low-pass filtered with tau = " << num(terms[j].tau) << " s";
    o << "\n";
  }
  return o.str();
}

std::vector<CncFile> twincat_files(const fitting::CncModel& m, const fitting::TableLaw& t,
                                   const std::string& source) {
  const auto n = t.positions.size();
  const auto nb = static_cast<Eigen::Index>(m.basis.size());
  std::ostringstream o;
  std::string head = header_lines("//", "TwinCAT NC table-based position compensation", source, m);
  o << "(*\n"
    << head << basis_list(m, "//")
    << "// Each PLC cycle (temperatures change slowly: once a second is enough) the PLC forms\n"
    << "// Compensation[i] = SUM_j b[j] * <axis>[j, i] and hands the table to\n"
    << "// MC_TableBasedPositionCompensation (Tc2_MC2) with ST_PositionCompensationTableParameter\n"
    << "// MinPosition, MaxPosition, NoOfTableElements below. Positions are the "
    << (m.feed_axis.empty() ? "axis" : m.feed_axis)
    << " axis's; for an axis\n// other than it, interpolate the table at its position in the PLC "
       "and "
       "write the value\n// with the axis's position correction (FB_WritePositionCorrection).\n*)\n"
    << "VAR_GLOBAL CONSTANT\n"
    << "  TT_MIN_POSITION : LREAL := " << num(t.positions(0) * kMillimetresPerMetre)
    << ";  (* mm *)\n"
    << "  TT_MAX_POSITION : LREAL := " << num(t.positions(n - 1) * kMillimetresPerMetre)
    << ";  (* mm *)\n"
    << "  TT_NO_OF_TABLE_ELEMENTS : UDINT := " << n << ";\n"
    << "  TT_NO_OF_BASIS : UDINT := " << nb << ";\n"
    << "END_VAR\n"
    << "(* Not CONSTANT: F_TtFormTable takes them by reference (VAR_IN_OUT). *)\n"
    << "VAR_GLOBAL\n";
  for (int d : acting_directions(m)) {
    o << "  (* " << kAxisLetters[d] << ": compensation [mm per basis unit], basis-major *)\n"
      << "  TT_COMP_" << kAxisLetters[d] << " : ARRAY[0.." << nb - 1 << ", 0.." << n - 1
      << "] OF LREAL := [\n";
    for (Eigen::Index j = 0; j < nb; ++j) {
      o << "    ";
      for (Eigen::Index i = 0; i < n; ++i)
        o << num(t.values[static_cast<std::size_t>(d)](i, j) * kMillimetresPerMetre)
          << (j == nb - 1 && i == n - 1 ? "" : ", ");
      o << "\n";
    }
    o << "  ];\n";
  }
  o << "END_VAR\n\n"
    << "FUNCTION F_TtFormTable : BOOL\n"
    << "VAR_IN_OUT\n  aTable : ARRAY[0.." << n - 1 << "] OF ST_PositionCompensationTableElement;\n"
    << "  aComp : ARRAY[0.." << nb - 1 << ", 0.." << n - 1 << "] OF LREAL;\nEND_VAR\n"
    << "VAR_INPUT\n  aBasis : ARRAY[0.." << nb - 1 << "] OF LREAL;  (* b[0] = 1 *)\nEND_VAR\n"
    << "VAR\n  i, j : UDINT;\nEND_VAR\n"
    << "FOR i := 0 TO " << n - 1 << " DO\n"
    << "  aTable[i].Position := TT_MIN_POSITION + (TT_MAX_POSITION - TT_MIN_POSITION) * "
    << "UDINT_TO_LREAL(i) / " << std::max<Eigen::Index>(n - 1, 1) << ".0;\n"
    << "  aTable[i].Compensation := 0;\n"
    << "  FOR j := 0 TO " << nb - 1 << " DO\n"
    << "    aTable[i].Compensation := aTable[i].Compensation + aBasis[j] * aComp[j, i];\n"
    << "  END_FOR\nEND_FOR\nF_TtFormTable := TRUE;\n";
  return {{"thermotwin_compensation.st", o.str()}, {"thermotwin_tables.csv", table_csv(m, t)}};
}

std::vector<CncFile> heidenhain_files(const fitting::CncModel& m, const fitting::TableLaw& t,
                                      const std::string& source) {
  std::vector<CncFile> files;
  const std::vector<int> dirs = acting_directions(m);
  const auto nb = static_cast<Eigen::Index>(m.basis.size());
  // One compensation-value table per basis function, in the *.COM layout: NR, AXISPOS, a column
  // per compensated axis [mm per basis unit].
  for (Eigen::Index j = 0; j < nb; ++j) {
    const std::string name = "TT_B" + std::string(j < 10 ? "0" : "") + std::to_string(j) + ".COM";
    std::ostringstream o;
    o << "BEGIN " << name << " MM\nNR AXISPOS";
    for (int d : dirs) o << " " << kAxisLetters[d];
    o << "\n";
    for (Eigen::Index i = 0; i < t.positions.size(); ++i) {
      o << i << " " << num(t.positions(i) * kMillimetresPerMetre);
      for (int d : dirs)
        o << " " << num(t.values[static_cast<std::size_t>(d)](i, j) * kMillimetresPerMetre);
      o << "\n";
    }
    o << "[END]\n";
    files.push_back({name, o.str()});
  }
  std::ostringstream p;
  p << header_lines(";", "HEIDENHAIN TNC thermal-expansion compensation (PLC)", source, m)
    << basis_list(m, ";")
    << "; The tables TT_B00.COM .. are in the compensation-value-table layout (NR, AXISPOS in mm\n"
    << "; along the " << (m.feed_axis.empty() ? "axis" : m.feed_axis)
    << " axis, one column per compensated axis, mm per basis unit); table j belongs to b[j].\n"
    << "; The TNC's nonlinear axis-error compensation (*.COM assigned in *.CMA) takes one active\n"
    << "; table line and cannot weight tables by temperature, so the PLC forms the value:\n"
    << ";   value(axis) = SUM_j b[j] * table_j(axis column, interpolated linearly at the "
    << (m.feed_axis.empty() ? "axis" : m.feed_axis) << " position)\n"
    << "; and hands it to module 9231 (compensation of thermal expansion) in 0.1 um, rounded,\n"
    << "; range -30000 .. +30000:\n";
  for (int d : dirs)
    p << ";   PS B/W/D/K <axis number of " << kAxisLetters[d] << ">  PS B/W/D/K <round(value("
      << kAxisLetters[d] << ") * 10000)>  CM 9231\n";
  files.push_back({"THERMOTWIN_9231.txt", p.str()});
  return files;
}

// ---- LinuxCNC --------------------------------------------------------------------------------

std::string hal_name(const std::string& s) {
  std::string out;
  for (char c : s) out += (std::isalnum(static_cast<unsigned char>(c)) || c == '-') ? c : '-';
  return out;
}

/// HAL nets: an output pin may sit on one signal only, so each writer gets one signal, named
/// once, and every reader joins it by name.
class HalNets {
 public:
  std::ostringstream text;
  /// Connects `reader` to the signal of `writer` (a pin), creating it the first time.
  void connect(const std::string& writer, const std::string& reader) {
    auto it = signal_.find(writer);
    if (it == signal_.end()) {
      it = signal_.emplace(writer, "tt-s" + std::to_string(signal_.size() + 1)).first;
      text << "net " << it->second << " " << writer << " => " << reader << "\n";
    } else {
      text << "net " << it->second << " => " << reader << "\n";
    }
  }

 private:
  std::map<std::string, std::string> signal_;
};

std::string lower(const char* axis) {
  return std::string(1, static_cast<char>(std::tolower(static_cast<unsigned char>(axis[0]))));
}

/// The HAL components a file loads, by kind, and the order the servo thread runs them in.
struct HalComponents {
  std::vector<std::string> sum2, mult2, lowpass, scale, conv, order;
  /// Adds `name` to `kind` and to the thread's order; returns it.
  std::string add(std::vector<std::string>& kind, const std::string& name) {
    kind.push_back(name);
    order.push_back(name);
    return name;
  }
};

/// The basis functions' output pins: increments reading - reference, and their low-pass filtered
/// versions.
std::vector<std::string> basis_pins(const std::vector<BasisTerm>& terms, HalComponents& comps,
                                    HalNets& nets) {
  std::vector<std::string> pin(terms.size());
  nets.text
      << "# Basis: the increments since the reference readings (set each tt-ref-* to the\n"
      << "# reading at the state the model starts from), low-pass filtered where the model\n"
      << "# says so. Connect each reading to its tt-in-* signal (degC; inputs in their unit).\n";
  for (std::size_t j = 0; j < terms.size(); ++j) {
    const std::string src = hal_name(terms[j].source);
    if (terms[j].tau == 0.0) {
      const std::string c = comps.add(comps.sum2, "tt-rise-" + src);
      nets.text << "net tt-in-" << src << " => " << c << ".in0\n"
                << "net tt-ref-" << src << " => " << c << ".in1\n"
                << "sets tt-ref-" << src << " 20.0\n"
                << "setp " << c << ".gain1 -1\n";
      pin[j] = c + ".out";
    } else {
      const std::string c =
          comps.add(comps.lowpass, hal_name("tt-lp" + num(terms[j].tau) + "-" + src));
      nets.connect("tt-rise-" + src + ".out", c + ".in");
      nets.text << "# gain = 1 - exp(-period/tau), period the servo thread's [s] (1 ms here)\n"
                << "setp " << c << ".gain " << num(1.0 - std::exp(-1e-3 / terms[j].tau)) << "\n";
      pin[j] = c + ".out";
    }
  }
  return pin;
}

/// Coefficient k of axis `ax` (row k of `c`, in m/m^k): a chain of sum2, two basis functions
/// each, the first taking the constant as its offset; returns the chain's output pin.
std::string coefficient_chain(const std::string& ax, Eigen::Index k, const Eigen::MatrixXd& c,
                              const std::vector<std::string>& pin, HalComponents& comps,
                              HalNets& nets) {
  const double to_mm = kMillimetresPerMetre /
                       std::pow(kMillimetresPerMetre, static_cast<double>(k));  // m/m^k -> mm/mm^k
  std::vector<std::size_t> used;  // basis functions with a coefficient
  for (std::size_t j = 0; j < pin.size(); ++j)
    if (c(k, static_cast<Eigen::Index>(j + 1)) != 0.0) used.push_back(j);
  std::string prev;
  std::size_t u = 0;
  for (int link = 0; link == 0 || u < used.size(); ++link) {
    const std::string sname =
        comps.add(comps.sum2, "tt-" + ax + "-c" + std::to_string(k) + "-" + std::to_string(link));
    for (const char* slot : {"0", "1"}) {
      if (slot[0] == '0' && !prev.empty()) {
        nets.connect(prev + ".out", sname + ".in0");
        continue;
      }
      if (u == used.size()) break;
      nets.connect(pin[used[u]], sname + ".in" + slot);
      nets.text << "setp " << sname << ".gain" << slot << " "
                << num(c(k, static_cast<Eigen::Index>(used[u] + 1)) * to_mm) << "\n";
      ++u;
    }
    if (prev.empty()) nets.text << "setp " << sname << ".offset " << num(c(k, 0) * to_mm) << "\n";
    prev = sname;
  }
  return prev + ".out";
}

/// Axis `d`'s offset: its coefficients, Horner's scheme in the feed position, then counts.
void axis_offset(const fitting::CncModel& m, const fitting::PolynomialLaw& law, int d,
                 const std::vector<std::string>& pin, HalComponents& comps, HalNets& nets) {
  const std::string position = "axis." + lower(kAxisLetters[m.feed_direction]) + ".pos-cmd";
  const std::string ax = lower(kAxisLetters[d]);
  const Eigen::MatrixXd& c = law.coefficients[static_cast<std::size_t>(d)];
  nets.text << "\n# " << kAxisLetters[d] << ": c_k = sum_j C[k][j] b[j] [mm / mm^k], offset = "
            << "c_0 + p (c_1 + p (c_2 + ...)), p = " << position << " [mm]\n";
  std::vector<std::string> coefficient_pin;
  for (Eigen::Index k = 0; k < c.rows(); ++k)
    coefficient_pin.push_back(coefficient_chain(ax, k, c, pin, comps, nets));
  // Horner: v = c_n; v = v p + c_k.
  std::string v = coefficient_pin.back();
  for (Eigen::Index k = c.rows() - 2; k >= 0; --k) {
    const std::string mul = comps.add(comps.mult2, "tt-" + ax + "-h" + std::to_string(k) + "-mul");
    const std::string add = comps.add(comps.sum2, "tt-" + ax + "-h" + std::to_string(k) + "-add");
    nets.connect(v, mul + ".in0");
    nets.connect(position, mul + ".in1");
    nets.connect(mul + ".out", add + ".in0");
    nets.connect(coefficient_pin[static_cast<std::size_t>(k)], add + ".in1");
    v = add + ".out";
  }
  const std::string sc = comps.add(comps.scale, "tt-" + ax + "-counts");
  const std::string cv = comps.add(comps.conv, "tt-" + ax + "-s32");
  nets.connect(v, sc + ".in");
  nets.text << "setp " << sc << ".gain " << num(1.0 / fitting::kLinuxcncScaleMm) << "\n";
  nets.connect(sc + ".out", cv + ".in");
  nets.connect(cv + ".out", "axis." + ax + ".eoffset-counts");
  nets.text << "setp axis." << ax << ".eoffset-scale " << num(fitting::kLinuxcncScaleMm) << "\n"
            << "setp axis." << ax << ".eoffset-enable 1\n";
}

/// The HAL file: its header, the components loaded and added to the servo thread, the nets.
std::string hal_text(const fitting::CncModel& m, const std::string& source,
                     const HalComponents& comps, const HalNets& nets) {
  std::ostringstream hal;
  hal << header_lines("#", "LinuxCNC external offsets (HAL)", source, m)
      << "# The offset is counts * eoffset-scale: truncated to " << num(fitting::kLinuxcncScaleMm)
      << " mm by conv_float_s32.\n";
  const auto load = [&](const char* comp, const std::vector<std::string>& names) {
    if (names.empty()) return;
    hal << "loadrt " << comp << " names=";
    for (std::size_t i = 0; i < names.size(); ++i) hal << (i ? "," : "") << names[i];
    hal << "\n";
  };
  load("sum2", comps.sum2);
  load("mult2", comps.mult2);
  load("lowpass", comps.lowpass);
  load("scale", comps.scale);
  load("conv_float_s32", comps.conv);
  hal << "\n# In data-flow order: the increments, the filters, then per axis its chain.\n";
  for (const auto& f : comps.order) hal << "addf " << f << " servo-thread\n";
  hal << "\n" << nets.text.str();
  return hal.str();
}

std::vector<CncFile> linuxcnc_files(const fitting::CncModel& m, const fitting::PolynomialLaw& law,
                                    const std::string& source) {
  HalComponents comps;
  HalNets nets;
  const std::vector<std::string> pin = basis_pins(basis_terms(m), comps, nets);
  const std::vector<int> dirs = acting_directions(m);
  for (int d : dirs) axis_offset(m, law, d, pin, comps, nets);
  std::ostringstream ini;
  ini << "# thermotwin export: INI entries for the external offsets of thermotwin_eoffset.hal\n"
      << "[HAL]\nHALFILE = thermotwin_eoffset.hal\n";
  for (int d : dirs)
    ini << "\n[AXIS_" << kAxisLetters[d] << "]\n"
        << "# fraction of MAX_VELOCITY and MAX_ACCELERATION kept for the external offset\n"
        << "OFFSET_AV_RATIO = 0.1\n";
  return {{"thermotwin_eoffset.hal", hal_text(m, source, comps, nets)},
          {"thermotwin_eoffset.ini", ini.str()}};
}

}  // namespace

std::string format_name(CncFormat format) {
  return std::string(core::name_in(kCncFormatNames, format));
}

CncFormat format_of(const std::string& name) {
  if (const auto format = core::value_in(kCncFormatNames, name)) return *format;
  throw core::DataError("--format '" + name + "': expected " + core::names_list(kCncFormatNames));
}

std::vector<CncFile> cnc_files(CncFormat format, const fitting::CncModel& model,
                               const fitting::ControllerLaw& law, const std::string& source) {
  switch (format) {
    case CncFormat::sinumerik:
      return sinumerik_files(model, std::get<fitting::LineLaw>(law), source);
    case CncFormat::twincat:
      return twincat_files(model, std::get<fitting::TableLaw>(law), source);
    case CncFormat::heidenhain:
      return heidenhain_files(model, std::get<fitting::TableLaw>(law), source);
    case CncFormat::linuxcnc:
      return linuxcnc_files(model, std::get<fitting::PolynomialLaw>(law), source);
  }
  return {};
}

}  // namespace tt::io
