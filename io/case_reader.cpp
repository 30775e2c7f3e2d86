// Reads a case file into core::CaseSpec. Every key is checked against the keys its table may
// hold, every value against its type and range, every name against what it refers to, and every
// failure names the file, the line, the key path and the value received.
#include "io/case_reader.hpp"

#include <toml++/toml.h>

#include <algorithm>
#include <cctype>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <map>
#include <optional>
#include <sstream>
#include <stdexcept>
#include <utility>
#include <vector>

#include "core/csv_cells.hpp"
#include "core/errors.hpp"
#include "core/limits.hpp"

namespace tt::io {

namespace {

namespace fs = std::filesystem;
using core::CaseError;
using core::CaseSpec;
using Names = std::vector<std::string>;

// ---------------------------------------------------------------------------------------------
// Text helpers shared by the reader (messages) and the writer (resolved TOML).

/// Shortest decimal that parses back to exactly `v`, in TOML float syntax.
std::string number_text(double v) {
  if (std::isnan(v)) return "nan";
  if (std::isinf(v)) return v > 0 ? "inf" : "-inf";
  char buf[64];
  const auto end = std::to_chars(buf, buf + sizeof buf, v).ptr;
  std::string s(buf, end);
  if (s.find_first_of(".e") == std::string::npos) s += ".0";
  return s;
}

/// A TOML basic string.
std::string toml_string(std::string_view s) {
  std::string out = "\"";
  for (const char ch : s) {
    const auto c = static_cast<unsigned char>(ch);
    if (ch == '"' || ch == '\\') {
      out += '\\';
      out += ch;
    } else if (c < 0x20 || c == 0x7f) {
      char buf[8];
      std::snprintf(buf, sizeof buf, "\\u%04X", c);
      out += buf;
    } else {
      out += ch;
    }
  }
  return out + "\"";
}

/// A TOML key: bare when it can be, quoted otherwise.
std::string key_text(std::string_view k) {
  const bool bare = !k.empty() && std::all_of(k.begin(), k.end(), [](char c) {
    return std::isalnum(static_cast<unsigned char>(c)) || c == '_' || c == '-';
  });
  return bare ? std::string(k) : toml_string(k);
}

std::string lower(std::string_view s) {
  std::string out(s);
  for (char& c : out) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return out;
}

/// Optimal-string-alignment distance (edits, adjacent swaps count one), case-insensitive.
std::size_t edit_distance(std::string_view a_in, std::string_view b_in) {
  const std::string a = lower(a_in), b = lower(b_in);
  std::vector<std::vector<std::size_t>> d(a.size() + 1, std::vector<std::size_t>(b.size() + 1));
  for (std::size_t i = 0; i <= a.size(); ++i) d[i][0] = i;
  for (std::size_t j = 0; j <= b.size(); ++j) d[0][j] = j;
  for (std::size_t i = 1; i <= a.size(); ++i) {
    for (std::size_t j = 1; j <= b.size(); ++j) {
      const std::size_t cost = a[i - 1] == b[j - 1] ? 0 : 1;
      d[i][j] = std::min({d[i - 1][j] + 1, d[i][j - 1] + 1, d[i - 1][j - 1] + cost});
      if (i > 1 && j > 1 && a[i - 1] == b[j - 2] && a[i - 2] == b[j - 1])
        d[i][j] = std::min(d[i][j], d[i - 2][j - 2] + 1);
    }
  }
  return d[a.size()][b.size()];
}

/// "did you mean 'x'?" for a near miss (a few edits, or the same key with/without its unit
/// suffix), otherwise the list of what is allowed.
std::string suggestion(std::string_view wrong, const Names& known) {
  if (known.empty()) return "nothing is declared to refer to";
  const std::string w = lower(wrong);
  std::string best;
  std::size_t best_d = std::string::npos;
  for (const auto& k : known) {
    std::size_t d = edit_distance(wrong, k);
    const std::string lk = lower(k);
    if (!w.empty() && (lk.rfind(w + "_", 0) == 0 || w.rfind(lk + "_", 0) == 0)) d = 1;
    if (d < best_d) best_d = d, best = k;
  }
  const std::size_t limit = std::max<std::size_t>(2, std::min<std::size_t>(4, wrong.size() / 3));
  if (best_d <= limit) return "did you mean '" + best + "'?";
  std::string list;
  for (const auto& k : known) list += (list.empty() ? "'" : ", '") + k + "'";
  return "expected one of " + list;
}

// ---------------------------------------------------------------------------------------------
// Reading context and typed access to TOML nodes.

struct Ctx {
  std::string file;           /// the case file as given, for messages
  fs::path dir;               /// folder that relative file names in the case resolve against
  double length_divisor = 1;  /// case length unit -> m: value / divisor (1 for m, 1000 for mm)
};

int line_of(const toml::node& n) {
  return static_cast<int>(n.source().begin.line);
}

[[noreturn]] void fail(const Ctx& c, int line, const std::string& message) {
  throw CaseError(core::located(c.file, line, message));
}

/// The value as it would be written in TOML, on one line (inline tables for tables).
std::string node_text(const toml::node& n) {
  if (const auto* x = n.as_string()) return toml_string(x->get());
  if (const auto* x = n.as_integer()) return std::to_string(x->get());
  if (const auto* x = n.as_floating_point()) return number_text(x->get());
  if (const auto* x = n.as_boolean()) return x->get() ? "true" : "false";
  if (const auto* a = n.as_array()) {
    std::string s = "[";
    for (std::size_t i = 0; i < a->size() && s.size() < 100; ++i)
      s += (i ? ", " : "") + node_text((*a)[i]);
    return s + "]";
  }
  if (const auto* t = n.as_table()) {
    std::string s = "{";
    for (auto&& [k, v] : *t) {
      if (s.size() >= 100) break;
      s += (s.size() > 1 ? ", " : " ") + key_text(k.str()) + " = " + node_text(v);
    }
    return s + (s.size() > 1 ? " }" : "}");
  }
  std::ostringstream os;  // dates and times: whatever toml++ writes
  os << toml::node_view<const toml::node>(&n);
  return os.str();
}

std::string value_text(const toml::node& n) {
  std::string s = node_text(n);
  if (s.size() > 80) s = s.substr(0, 77) + "...";
  return s;
}

/// "path = value: expected[; hint]" at the node's line.
[[noreturn]] void fail_value(const Ctx& c, const toml::node& n, const std::string& path,
                             const std::string& expected, const std::string& hint = {}) {
  fail(c, line_of(n),
       path + " = " + value_text(n) + ": " + expected + (hint.empty() ? "" : "; " + hint));
}

std::string type_name(const toml::node& n) {
  switch (n.type()) {
    case toml::node_type::table:
      return "a table";
    case toml::node_type::array:
      return "an array";
    case toml::node_type::string:
      return "a string";
    case toml::node_type::integer:
      return "an integer";
    case toml::node_type::floating_point:
      return "a float";
    case toml::node_type::boolean:
      return "a boolean";
    default:
      return "a date/time";
  }
}

[[noreturn]] void fail_type(const Ctx& c, const toml::node& n, const std::string& path,
                            const std::string& expected, const std::string& hint = {}) {
  fail_value(c, n, path, "expected " + expected + ", got " + type_name(n), hint);
}

/// A table being read, with its key path ("materials.steel", "bodies[1].add[0].cylinder").
struct Tab {
  const Ctx* ctx;
  const toml::table* t;
  std::string path;

  std::string at(std::string_view key) const {
    return path.empty() ? std::string(key) : path + "." + std::string(key);
  }
  const toml::node* get(std::string_view key) const { return t->get(key); }
  int line() const { return line_of(*t); }

  /// Every key present must be one of `known`.
  void allow(const Names& known) const {
    for (auto&& [k, v] : *t) {
      if (std::find(known.begin(), known.end(), k.str()) != known.end()) continue;
      fail(*ctx, static_cast<int>(k.source().begin.line),
           at(k.str()) + " = " + value_text(v) + ": unknown key; " + suggestion(k.str(), known));
    }
  }

  const toml::node& need(std::string_view key, const std::string& expected) const {
    const toml::node* n = get(key);
    if (!n) {
      fail(*ctx, line(),
           at(key) + ": missing; expected " + expected + " in " +
               (path.empty() ? "the file" : path));
    }
    return *n;
  }
};

Tab as_tab(const Ctx& c, const toml::node& n, const std::string& path,
           const std::string& expected = "a table") {
  if (!n.is_table()) fail_type(c, n, path, expected);
  return Tab{&c, n.as_table(), path};
}

double as_number(const Ctx& c, const toml::node& n, const std::string& path) {
  double v = 0;
  if (const auto* f = n.as_floating_point()) {
    v = f->get();
  } else if (const auto* i = n.as_integer()) {
    v = static_cast<double>(i->get());
  } else {
    fail_type(c, n, path, "a number");
  }
  if (!std::isfinite(v)) fail_value(c, n, path, "must be a finite number");
  return v;
}

enum class Sign { any, positive, non_negative };

double checked(const Ctx& c, const toml::node& n, const std::string& path, Sign sign,
               const std::string& hint) {
  const double v = as_number(c, n, path);
  if (sign == Sign::positive && !(v > 0)) fail_value(c, n, path, "must be > 0", hint);
  if (sign == Sign::non_negative && v < 0) fail_value(c, n, path, "must be >= 0", hint);
  return v;
}

double number(const Tab& t, std::string_view key, Sign sign = Sign::any,
              const std::string& hint = {}) {
  return checked(*t.ctx, t.need(key, "a number"), t.at(key), sign, hint);
}

double number_or(const Tab& t, std::string_view key, double fallback, Sign sign = Sign::any,
                 const std::string& hint = {}) {
  const toml::node* n = t.get(key);
  return n ? checked(*t.ctx, *n, t.at(key), sign, hint) : fallback;
}

/// A length in the case's unit, returned in m.
double length(const Tab& t, std::string_view key, Sign sign = Sign::positive,
              const std::string& hint = "a length in [geometry] length_unit") {
  return number(t, key, sign, hint) / t.ctx->length_divisor;
}

/// A temperature in degC: finite and not below absolute zero.
double temperature_c(const Ctx& c, const toml::node& n, const std::string& path) {
  const double v = as_number(c, n, path);
  if (v < core::limits::kAbsoluteZeroDegC)
    fail_value(c, n, path, "must be >= -273.15 degC (absolute zero)",
               "temperatures in the case are in degC, not K");
  return v;
}

double temperature_or(const Tab& t, std::string_view key, double fallback) {
  const toml::node* n = t.get(key);
  return n ? temperature_c(*t.ctx, *n, t.at(key)) : fallback;
}

std::int64_t integer(const Ctx& c, const toml::node& n, const std::string& path) {
  if (const auto* i = n.as_integer()) return i->get();
  fail_type(c, n, path, "an integer", "write it without a decimal point");
}

std::string as_string(const Ctx& c, const toml::node& n, const std::string& path) {
  if (const auto* s = n.as_string()) return s->get();
  fail_type(c, n, path, "a string", "put it in double quotes");
}

/// A non-empty string.
std::string name(const Tab& t, std::string_view key) {
  const auto& n = t.need(key, "a string");
  std::string s = as_string(*t.ctx, n, t.at(key));
  if (s.empty()) fail_value(*t.ctx, n, t.at(key), "must not be empty");
  return s;
}

bool flag_or(const Tab& t, std::string_view key, bool fallback) {
  const toml::node* n = t.get(key);
  if (!n) return fallback;
  if (const auto* b = n->as_boolean()) return b->get();
  fail_type(*t.ctx, *n, t.at(key), "true or false");
}

const toml::array& as_array(const Ctx& c, const toml::node& n, const std::string& path,
                            const std::string& expected = "an array") {
  if (!n.is_array()) fail_type(c, n, path, expected);
  return *n.as_array();
}

template <class E>
using Choices = std::vector<std::pair<std::string, E>>;

template <class E>
E choice(const Ctx& c, const toml::node& n, const std::string& path, const Choices<E>& choices) {
  const std::string s = as_string(c, n, path);
  Names names;
  for (const auto& [k, e] : choices) {
    if (k == s) return e;
    names.push_back(k);
  }
  fail_value(c, n, path, "unknown value", suggestion(s, names));
}

template <class E>
E choice_or(const Tab& t, std::string_view key, E fallback, const Choices<E>& choices) {
  const toml::node* n = t.get(key);
  return n ? choice(*t.ctx, *n, t.at(key), choices) : fallback;
}

// The names a case file gives each enum's values, read by `choice` and written back by
// `resolved_case_toml`. A value the solvers cannot run has no name here, so the reader refuses it.
const Choices<core::TimeScheme> kSchemes = {{"backward_euler", core::TimeScheme::backward_euler},
                                            {"crank_nicolson", core::TimeScheme::crank_nicolson}};
const Choices<core::FaceSelector::Side> kSides = {
    {"exterior", core::FaceSelector::Side::exterior},
    {"interface", core::FaceSelector::Side::interface},
    {"any", core::FaceSelector::Side::any}};
const Choices<core::HeatSource::Law> kLaws = {{"speed_power", core::HeatSource::Law::speed_power},
                                              {"constant", core::HeatSource::Law::constant},
                                              {"palmgren", core::HeatSource::Law::palmgren},
                                              {"feed_power", core::HeatSource::Law::feed_power}};
const Choices<core::PlacementSpec::Candidates> kCandidateKinds = {
    {"points", core::PlacementSpec::Candidates::points},
    {"surface", core::PlacementSpec::Candidates::surface}};

/// The name `choices` gives `e`; every value of a spec read from a case has one.
template <class E>
const std::string& name_of(const Choices<E>& choices, E e) {
  for (const auto& [name, value] : choices)
    if (value == e) return name;
  throw std::logic_error("case_reader: an enum value with no name in its table");
}

/// Index of `n`'s string among `names`; `what` names the kind ("body", "boundary group").
int reference(const Ctx& c, const toml::node& n, const std::string& path, const Names& names,
              const std::string& what) {
  const std::string s = as_string(c, n, path);
  const auto it = std::find(names.begin(), names.end(), s);
  if (it != names.end()) return static_cast<int>(it - names.begin());
  fail_value(c, n, path, "no " + what + " of that name", suggestion(s, names));
}

int reference(const Tab& t, std::string_view key, const Names& names, const std::string& what) {
  return reference(*t.ctx, t.need(key, "the name of a " + what), t.at(key), names, what);
}

std::vector<int> references(const Ctx& c, const toml::node& n, const std::string& path,
                            const Names& names, const std::string& what) {
  const auto& a = as_array(c, n, path, "an array of " + what + " names");
  std::vector<int> out;
  for (std::size_t i = 0; i < a.size(); ++i) {
    const std::string p = path + "[" + std::to_string(i) + "]";
    const int r = reference(c, a[i], p, names, what);
    if (std::find(out.begin(), out.end(), r) != out.end())
      fail_value(c, a[i], p, "listed twice", "name each " + what + " once");
    out.push_back(r);
  }
  return out;
}

/// Fixed-size list of finite numbers.
Eigen::VectorXd numbers(const Ctx& c, const toml::node& n, const std::string& path, int count,
                        const std::string& shape) {
  const auto& a = as_array(c, n, path, "an array " + shape);
  if (static_cast<int>(a.size()) != count)
    fail_value(c, n, path, "expected " + std::to_string(count) + " numbers " + shape);
  Eigen::VectorXd v(count);
  for (int i = 0; i < count; ++i) v[i] = as_number(c, a[i], path + "[" + std::to_string(i) + "]");
  return v;
}

Eigen::Vector3d point3(const Tab& t, std::string_view key) {
  return numbers(*t.ctx, t.need(key, "[x, y, z]"), t.at(key), 3, "[x, y, z]") /
         t.ctx->length_divisor;
}

Eigen::Vector2d axis2(const Tab& t, std::string_view key) {
  return numbers(*t.ctx, t.need(key, "[x, y] of the z-parallel axis"), t.at(key), 2, "[x, y]") /
         t.ctx->length_divisor;
}

/// Array of tables (`[[key]]` or an array of inline tables), each passed to `read` with its path.
template <class F>
void each_table(const Tab& t, std::string_view key, F&& read) {
  const toml::node* n = t.get(key);
  if (!n) return;
  const std::string path = t.at(key);
  const auto& a = as_array(*t.ctx, *n, path, "an array of tables ([[" + path + "]])");
  for (std::size_t i = 0; i < a.size(); ++i) {
    const std::string p = path + "[" + std::to_string(i) + "]";
    read(as_tab(*t.ctx, a[i], p), i);
  }
}

/// The case file's length unit as a divisor to m.
double unit_divisor(const Ctx& c, const toml::node& n, const std::string& path) {
  return choice<double>(c, n, path, {{"m", 1.0}, {"mm", 1000.0}});
}

void check_box(const Ctx& c, const Tab& t, const Eigen::Vector3d& lo, const Eigen::Vector3d& hi) {
  for (int i = 0; i < 3; ++i) {
    if (!(lo[i] < hi[i])) {
      fail_value(c, t.need("max", ""), t.at("max"),
                 "must exceed min = " + value_text(t.need("min", "")) + " in every coordinate (" +
                     std::string(1, "xyz"[i]) + " is not)",
                 "min is the lower corner, max the upper one");
    }
  }
}

/// z = [z0, z1] with z0 < z1, in m.
std::pair<double, double> z_range(const Tab& t) {
  const auto& n = t.need("z", "[z0, z1]");
  const Eigen::VectorXd z = numbers(*t.ctx, n, t.at("z"), 2, "[z0, z1]");
  if (!(z[0] < z[1])) fail_value(*t.ctx, n, t.at("z"), "must have z0 < z1", "z = [start, end]");
  return {z[0] / t.ctx->length_divisor, z[1] / t.ctx->length_divisor};
}

// ---------------------------------------------------------------------------------------------
// Sections.

void read_header(const Tab& root, CaseSpec& spec) {
  const Tab c = as_tab(*root.ctx, root.need("case", "a [case] table with name"), "case");
  c.allow({"name", "machine", "seed"});
  spec.name = name(c, "name");
  if (const auto* m = c.get("machine")) spec.machine = as_string(*c.ctx, *m, c.at("machine"));
  if (const auto* s = c.get("seed")) {
    const auto v = integer(*c.ctx, *s, c.at("seed"));
    if (v < 0) fail_value(*c.ctx, *s, c.at("seed"), "must be >= 0");
    spec.seed = static_cast<std::uint64_t>(v);
  }
}

Names material_keys() {
  return {"density_kg_m3",     "specific_heat_J_kgK", "conductivity_W_mK",
          "youngs_modulus_Pa", "poisson_ratio",       "expansion_per_K"};
}

void read_materials(const Tab& root, CaseSpec& spec) {
  const Tab all =
      as_tab(*root.ctx, root.need("materials", "[materials.<name>] tables"), "materials");
  // toml++ keeps keys sorted; the case's order is the order of declaration.
  std::vector<std::pair<const toml::key*, const toml::node*>> entries;
  for (auto&& [k, v] : *all.t) entries.emplace_back(&k, &v);
  std::sort(entries.begin(), entries.end(), [](const auto& a, const auto& b) {
    const auto &sa = a.first->source().begin, &sb = b.first->source().begin;
    return std::tie(sa.line, sa.column) < std::tie(sb.line, sb.column);
  });
  if (entries.empty()) fail(*root.ctx, all.line(), "materials: none declared");
  for (const auto& [k, v] : entries) {
    const Tab m = as_tab(*root.ctx, *v, all.at(k->str()), "a [materials.<name>] table");
    m.allow(material_keys());
    core::Material mat;
    mat.name = k->str();
    mat.density = number(m, "density_kg_m3", Sign::positive, "a density in kg/m^3, steel is 7850");
    mat.specific_heat =
        number(m, "specific_heat_J_kgK", Sign::positive, "in J/(kg K), steel is about 460");
    mat.conductivity =
        number(m, "conductivity_W_mK", Sign::positive, "in W/(m K), steel is about 45");
    mat.youngs_modulus =
        number(m, "youngs_modulus_Pa", Sign::positive, "in Pa, steel is about 2.1e11");
    const auto& nu = m.need("poisson_ratio", "a number in (-1, 0.5)");
    mat.poisson_ratio = as_number(*m.ctx, nu, m.at("poisson_ratio"));
    if (!(mat.poisson_ratio > -1 && mat.poisson_ratio < 0.5))
      fail_value(*m.ctx, nu, m.at("poisson_ratio"), "must lie in (-1, 0.5)",
                 "0.5 is incompressible and singular; metals are about 0.3");
    mat.expansion = number(m, "expansion_per_K", Sign::any, "in 1/K, steel is about 1.2e-5");
    spec.materials.push_back(mat);
  }
}

core::Primitive read_primitive(const Tab& p, const std::string& where) {
  const Ctx& c = *p.ctx;
  const Names kinds = {"box", "cylinder", "annulus", "surface"};
  p.allow(kinds);
  if (p.t->size() != 1) {
    fail(c, p.line(),
         where + " = " + value_text(*p.t) +
             ": expected exactly one of 'box', 'cylinder', 'annulus', 'surface'");
  }
  // toml++ iterators hand out a proxy that lives inside the iterator: keep the iterator alive.
  const auto only = p.t->begin();
  const std::string key(only->first.str());
  const toml::node& node = only->second;
  core::Primitive prim;
  prim.where = where;
  const Tab s = as_tab(c, node, p.at(key), "an inline table");
  if (key == "box") {
    s.allow({"min", "max"});
    prim.kind = core::Primitive::Kind::box;
    prim.min = point3(s, "min");
    prim.max = point3(s, "max");
    check_box(c, s, prim.min, prim.max);
  } else if (key == "cylinder") {
    s.allow({"axis", "radius", "z"});
    prim.kind = core::Primitive::Kind::cylinder;
    prim.axis = axis2(s, "axis");
    prim.radius = length(s, "radius");
    std::tie(prim.z_min, prim.z_max) = z_range(s);
  } else if (key == "annulus") {
    s.allow({"axis", "inner_radius", "outer_radius", "z"});
    prim.kind = core::Primitive::Kind::annulus;
    prim.axis = axis2(s, "axis");
    prim.inner_radius = length(s, "inner_radius", Sign::positive, "use a cylinder for a solid");
    prim.radius = length(s, "outer_radius");
    if (!(prim.inner_radius < prim.radius))
      fail_value(c, s.need("outer_radius", ""), s.at("outer_radius"),
                 "must exceed inner_radius = " + value_text(s.need("inner_radius", "")));
    std::tie(prim.z_min, prim.z_max) = z_range(s);
  } else {
    s.allow({"file", "unit"});
    prim.kind = core::Primitive::Kind::surface_file;
    const auto& fn = s.need("file", "a path relative to the case file");
    const std::string rel = as_string(c, fn, s.at("file"));
    prim.file = fs::absolute(c.dir / rel).lexically_normal();
    std::error_code ec;
    if (rel.empty() || !fs::is_regular_file(prim.file, ec))
      fail_value(c, fn, s.at("file"), "no such file (looked for " + prim.file.string() + ")",
                 "paths are relative to the case file's folder");
    const std::string ext = lower(prim.file.extension().string());
    if (ext != ".stl" && ext != ".off" && ext != ".ply")
      fail_value(c, fn, s.at("file"), "expected a closed surface in STL, OFF or PLY format");
    const double divisor =
        s.get("unit") ? unit_divisor(c, *s.get("unit"), s.at("unit")) : c.length_divisor;
    prim.file_scale = 1.0 / divisor;
  }
  return prim;
}

std::vector<core::Primitive> read_primitives(const Tab& b, std::string_view key, bool required) {
  std::vector<core::Primitive> out;
  const toml::node* n = b.get(key);
  if (!n && !required) return out;
  const std::string path = b.at(key);
  const auto& a = as_array(*b.ctx, b.need(key, "an array of primitives"), path,
                           "an array of { box | cylinder | annulus | surface = {...} }");
  if (required && a.empty())
    fail_value(*b.ctx, *n, path, "must list at least one primitive", "e.g. [ { box = {...} } ]");
  for (std::size_t i = 0; i < a.size(); ++i) {
    const std::string p = path + "[" + std::to_string(i) + "]";
    out.push_back(read_primitive(as_tab(*b.ctx, a[i], p, "an inline table"), p));
  }
  return out;
}

Names names_of(const auto& items) {
  Names out;
  for (const auto& x : items) out.push_back(x.name);
  return out;
}

/// Fails when `value` is already among the names read so far.
void unique(const Tab& t, std::string_view key, const std::string& value, const Names& before,
            const std::string& what) {
  if (std::find(before.begin(), before.end(), value) != before.end())
    fail_value(*t.ctx, t.need(key, ""), t.at(key), "a second " + what + " of that name",
               "names must be unique");
}

void read_bodies(const Tab& root, CaseSpec& spec) {
  root.need("bodies", "[[bodies]] tables");
  const Names materials = names_of(spec.materials);
  each_table(root, "bodies", [&](const Tab& b, std::size_t) {
    b.allow({"name", "material", "max_edge", "add", "subtract"});
    core::Body body;
    body.name = name(b, "name");
    unique(b, "name", body.name, names_of(spec.bodies), "body");
    body.material = reference(b, "material", materials, "material");
    body.max_edge = length(b, "max_edge", Sign::positive, "the target tet edge length");
    body.add = read_primitives(b, "add", true);
    body.subtract = read_primitives(b, "subtract", false);
    spec.bodies.push_back(body);
  });
  if (spec.bodies.empty()) fail(*root.ctx, line_of(*root.get("bodies")), "bodies: none declared");
}

constexpr std::int64_t kMinCircleSegments = 8, kMaxCircleSegments = 100000;
/// TetGen 1.5's -q refinement stalls above about 18 deg (its manual); the adapter refuses more.
constexpr double kMaxMinDihedralDeg = 18;
/// Below about 1.1 TetGen's -q refinement may not terminate (its manual).
constexpr double kMinRadiusEdgeRatio = 1.1;

void read_mesh(const Tab& root, CaseSpec& spec) {
  const toml::node* n = root.get("mesh");
  if (!n) return;
  const Tab m = as_tab(*root.ctx, *n, "mesh");
  m.allow({"order", "circle_segments", "radius_edge_ratio", "min_dihedral_deg", "max_tets",
           "time_limit_s", "memory_limit_GB"});
  if (const auto* o = m.get("order")) {
    const auto v = integer(*m.ctx, *o, m.at("order"));
    if (v != 1 && v != 2)
      fail_value(*m.ctx, *o, m.at("order"), "must be 1 or 2",
                 "1: 4-node tetrahedra, 2: 10-node (needed for thermal bending)");
    spec.mesh.order = static_cast<int>(v);
  }
  if (const auto* s = m.get("circle_segments")) {
    const auto v = integer(*m.ctx, *s, m.at("circle_segments"));
    if (v < kMinCircleSegments || v > kMaxCircleSegments)
      fail_value(*m.ctx, *s, m.at("circle_segments"),
                 "must lie in [" + std::to_string(kMinCircleSegments) + ", " +
                     std::to_string(kMaxCircleSegments) + "]",
                 "facets around each cylinder; 48 keeps the radius within 0.2 %");
    spec.mesh.circle_segments = static_cast<int>(v);
  }
  if (const auto* r = m.get("radius_edge_ratio")) {
    spec.mesh.radius_edge_ratio = as_number(*m.ctx, *r, m.at("radius_edge_ratio"));
    if (!(spec.mesh.radius_edge_ratio >= kMinRadiusEdgeRatio))
      fail_value(*m.ctx, *r, m.at("radius_edge_ratio"), "must be >= 1.1",
                 "TetGen's refinement may not terminate below about 1.1; 1.5 is a good default");
  }
  if (const auto* d = m.get("min_dihedral_deg")) {
    spec.mesh.min_dihedral_deg = as_number(*m.ctx, *d, m.at("min_dihedral_deg"));
    if (!(spec.mesh.min_dihedral_deg >= 0 && spec.mesh.min_dihedral_deg <= kMaxMinDihedralDeg))
      fail_value(*m.ctx, *d, m.at("min_dihedral_deg"), "must lie in [0, 18]",
                 "TetGen's quality meshing manages at most about 18 deg; 12 is a good default");
  }
  auto& mesh = spec.mesh;
  mesh.max_tets = number_or(m, "max_tets", mesh.max_tets, Sign::positive,
                            "tetrahedra estimated before meshing; raise it for a finer mesh");
  mesh.time_limit_s = number_or(m, "time_limit_s", mesh.time_limit_s, Sign::positive,
                                "wall time TetGen may take, in s");
  mesh.memory_limit_GB = number_or(m, "memory_limit_GB", mesh.memory_limit_GB, Sign::positive,
                                   "memory TetGen may take, in GB");
}

core::FaceSelector read_selector(const Tab& s, const Names& bodies) {
  const Ctx& c = *s.ctx;
  s.allow({"bodies", "side", "other_bodies", "plane", "on_cylinder", "within"});
  core::FaceSelector sel;
  using Side = core::FaceSelector::Side;
  if (const auto* b = s.get("bodies"))
    sel.bodies = references(c, *b, s.at("bodies"), bodies, "body");
  sel.side = choice_or<Side>(s, "side", Side::exterior, kSides);
  if (const auto* o = s.get("other_bodies")) {
    if (sel.side != Side::interface)
      fail_value(c, *o, s.at("other_bodies"), "only meaningful with side = \"interface\"",
                 "exterior faces have no body across them");
    sel.other_bodies = references(c, *o, s.at("other_bodies"), bodies, "body");
  }
  if (const auto* p = s.get("plane")) {
    const Tab pt = as_tab(c, *p, s.at("plane"), "{ normal = [x, y, z], offset = d }");
    pt.allow({"normal", "offset"});
    const auto& nn = pt.need("normal", "[x, y, z]");
    const Eigen::Vector3d normal = numbers(c, nn, pt.at("normal"), 3, "[x, y, z]");
    const double norm = normal.norm();
    if (!(norm > 0)) fail_value(c, nn, pt.at("normal"), "must not be zero", "e.g. [0, 1, 0]");
    const double offset = number(pt, "offset") / c.length_divisor;
    sel.plane =
        Eigen::Vector4d(normal.x() / norm, normal.y() / norm, normal.z() / norm, offset / norm);
  }
  if (const auto* oc = s.get("on_cylinder")) {
    const Tab ct = as_tab(c, *oc, s.at("on_cylinder"), "{ axis = [x, y], radius = r }");
    ct.allow({"axis", "radius"});
    sel.on_cylinder = core::FaceSelector::Cylinder{axis2(ct, "axis"), length(ct, "radius")};
  }
  if (const auto* w = s.get("within")) {
    const Tab wt = as_tab(c, *w, s.at("within"), "{ min = [x, y, z], max = [x, y, z] }");
    wt.allow({"min", "max"});
    sel.within_min = point3(wt, "min");
    sel.within_max = point3(wt, "max");
    check_box(c, wt, *sel.within_min, *sel.within_max);
  }
  return sel;
}

void read_boundary(const Tab& root, CaseSpec& spec) {
  const Names bodies = names_of(spec.bodies);
  each_table(root, "boundary", [&](const Tab& g, std::size_t) {
    g.allow({"name", "rest", "select"});
    core::BoundaryGroup group;
    group.name = name(g, "name");
    unique(g, "name", group.name, names_of(spec.groups), "boundary group");
    group.rest = flag_or(g, "rest", false);
    const auto& sn = g.need("select", "an array of selectors");
    const auto& a = as_array(*g.ctx, sn, g.at("select"), "an array of { bodies = [...], ... }");
    if (a.empty())
      fail_value(*g.ctx, sn, g.at("select"), "must hold at least one selector",
                 "{} selects every exterior face");
    for (std::size_t i = 0; i < a.size(); ++i) {
      const std::string p = g.at("select") + "[" + std::to_string(i) + "]";
      group.select.push_back(read_selector(as_tab(*g.ctx, a[i], p, "an inline table"), bodies));
    }
    spec.groups.push_back(group);
  });
}

void read_points(const Tab& root, CaseSpec& spec) {
  const toml::node* n = root.get("points");
  if (!n) return;
  const Tab pts = as_tab(*root.ctx, *n, "points");
  pts.allow({"list"});
  const Names groups = names_of(spec.groups);
  Names ids;
  each_table(pts, "list", [&](const Tab& p, std::size_t) {
    p.allow({"id", "position", "on"});
    core::NamedPoint pt;
    pt.id = name(p, "id");
    unique(p, "id", pt.id, ids, "point");
    ids.push_back(pt.id);
    pt.position = point3(p, "position");
    if (p.get("on")) pt.on_group = reference(p, "on", groups, "boundary group");
    spec.points.push_back(pt);
  });
}

Names point_ids(const CaseSpec& spec) {
  Names out;
  for (const auto& p : spec.points) out.push_back(p.id);
  return out;
}

/// Segments from the text of a CSV "time_s,speed_rpm" with a header; errors name `file` and the
/// line, then `where` (what named the file).
std::vector<core::DutyCycle::Segment> parse_duty_cycle_csv(const std::string& bytes,
                                                           const fs::path& file,
                                                           const std::string& where) {
  std::istringstream in(bytes);
  auto csv_fail = [&](int line, const std::string& msg) -> void {
    throw CaseError(core::located(file.string(), line, msg + where));
  };
  std::vector<core::DutyCycle::Segment> out;
  std::string text;
  int line = 0;
  bool header = false;
  while (std::getline(in, text)) {
    ++line;
    text = std::string(core::trimmed(text));
    if (text.empty() || text[0] == '#') continue;
    std::size_t at = 0;
    const std::string a(core::next_cell(text, at));
    // The rest of the line is the second cell: a third cell makes it no number.
    const std::string b(at == std::string::npos
                            ? std::string_view()
                            : core::cell_content(std::string_view(text).substr(at)));
    if (!header) {
      if (a != "time_s" || b != "speed_rpm")
        csv_fail(line, "header = \"" + text + "\": expected \"time_s,speed_rpm\"");
      header = true;
      continue;
    }
    double v[2];
    const std::string cells[2] = {a, b};
    for (int i = 0; i < 2; ++i) {
      const std::optional<double> number = core::cell_number(cells[i]);
      if (!number || !std::isfinite(*number))
        csv_fail(line, std::string(i ? "speed_rpm" : "time_s") + " = \"" + cells[i] +
                           "\": expected a finite number");
      v[i] = *number;
    }
    if (out.empty() && v[0] != 0)
      csv_fail(line, "time_s = " + number_text(v[0]) + ": the first row must start at 0");
    if (!out.empty() && !(v[0] > out.back().start))
      csv_fail(line, "time_s = " + number_text(v[0]) + ": must exceed the previous row's " +
                         number_text(out.back().start) + "; times must ascend");
    if (v[1] < 0) csv_fail(line, "speed_rpm = " + number_text(v[1]) + ": must be >= 0");
    out.push_back({v[0], v[1]});
  }
  if (out.empty()) csv_fail(line, "no data rows: expected \"time_s,speed_rpm\" then rows");
  return out;
}

/// Segments of the CSV that duty_cycle.csv names; errors point into the CSV and at the key.
std::vector<core::DutyCycle::Segment> csv_segments(const Ctx& c, const toml::node& n,
                                                   const std::string& path) {
  std::string rel = as_string(c, n, path);
  const fs::path file = c.dir / rel;
  using core::limits::kDutyCycleFileBytes;
  std::optional<std::string> bytes;
  try {
    if (!rel.empty()) bytes = core::limits::file_text_up_to(file, kDutyCycleFileBytes);
  } catch (const core::IoError&) {
    rel.clear();
  }
  if (rel.empty())
    fail_value(c, n, path, "cannot read " + file.string(),
               "paths are relative to the case file's folder");
  if (!bytes)
    fail_value(c, n, path,
               file.string() + " holds more than " + core::limits::bytes_text(kDutyCycleFileBytes) +
                   ", the limit for a duty-cycle CSV",
               "a row per speed change is enough");
  return parse_duty_cycle_csv(*bytes, file, " (" + path + " of " + c.file + ")");
}

void read_duty_cycle(const Tab& root, CaseSpec& spec) {
  const Tab d = as_tab(*root.ctx, root.need("duty_cycle", "a [duty_cycle] table"), "duty_cycle");
  const Ctx& c = *d.ctx;
  d.allow({"end_s", "segments", "csv"});
  spec.duty_cycle.end = number(d, "end_s", Sign::positive, "the run's length in s");
  const toml::node* seg = d.get("segments");
  const toml::node* csv = d.get("csv");
  if (seg && csv) fail_value(c, *csv, d.at("csv"), "give either segments or csv, not both");
  if (!seg && !csv)
    fail(c, d.line(),
         "duty_cycle.segments: missing; expected segments = [{ start_s, speed_rpm }, "
         "...] or csv = \"file.csv\"");
  if (csv) {
    spec.duty_cycle.segments = csv_segments(c, *csv, d.at("csv"));
    spec.duty_cycle.csv = fs::absolute(c.dir / *csv->value<std::string>()).lexically_normal();
  } else {
    each_table(d, "segments", [&](const Tab& s, std::size_t i) {
      s.allow({"start_s", "speed_rpm"});
      const auto& sn = s.need("start_s", "a time in s");
      const double start = as_number(c, sn, s.at("start_s"));
      if (i == 0 && start != 0)
        fail_value(c, sn, s.at("start_s"), "the first segment must start at 0");
      if (i > 0 && !(start > spec.duty_cycle.segments.back().start))
        fail_value(
            c, sn, s.at("start_s"),
            "must exceed the previous start " + number_text(spec.duty_cycle.segments.back().start),
            "segments must be in ascending time order");
      const double rpm =
          number(s, "speed_rpm", Sign::non_negative, "the speed's magnitude; 0 is standstill");
      spec.duty_cycle.segments.push_back({start, rpm});
    });
    if (spec.duty_cycle.segments.empty())
      fail_value(c, *seg, d.at("segments"), "must hold at least one segment");
  }
  if (!(spec.duty_cycle.end > spec.duty_cycle.segments.back().start))
    fail_value(c, d.need("end_s", ""), d.at("end_s"),
               "must exceed the last segment's start " +
                   number_text(spec.duty_cycle.segments.back().start));
}

/// A feed speed in m/s from `<stem>_m_min` (as people write it) or `<stem>_m_s` (as the resolved
/// case writes it, exactly), one of the two.
double feed_speed(const Tab& t, const std::string& stem, Sign sign) {
  const std::string per_min = stem + "_m_min", per_s = stem + "_m_s";
  const toml::node* a = t.get(per_min);
  const toml::node* b = t.get(per_s);
  if (a && b)
    fail_value(*t.ctx, *b, t.at(per_s), "give either " + per_min + " or " + per_s + ", not both");
  if (b) return number(t, per_s, sign, "feed speed in m/s");
  return number(t, per_min, sign, "feed speed in m/min") / 60.0;
}

core::TimeTable sink_table(const Ctx& c, const toml::node& n, const std::string& path) {
  const auto& a = as_array(c, n, path, "[[t_s, degC], ...]");
  if (a.empty()) fail_value(c, n, path, "must hold at least one [t_s, degC] row");
  core::TimeTable table;
  for (std::size_t i = 0; i < a.size(); ++i) {
    const std::string p = path + "[" + std::to_string(i) + "]";
    const Eigen::VectorXd row = numbers(c, a[i], p, 2, "[t_s, degC]");
    temperature_c(c, (*a[i].as_array())[1], p + "[1]");
    if (!table.time.empty() && !(row[0] > table.time.back()))
      fail_value(c, a[i], p,
                 "time must exceed the previous row's " + number_text(table.time.back()),
                 "rows in ascending time");
    table.time.push_back(row[0]);
    table.value.push_back(row[1]);
  }
  return table;
}

/// A convection entry's sink: sink_degC (constant) or sink_table (over time), one of the two.
core::TimeTable convection_sink(const Tab& cv) {
  const Ctx& c = *cv.ctx;
  const toml::node* sd = cv.get("sink_degC");
  const toml::node* st = cv.get("sink_table");
  if (sd && st)
    fail_value(c, *st, cv.at("sink_table"), "give either sink_degC or sink_table, not both");
  if (st) return sink_table(c, *st, cv.at("sink_table"));
  if (!sd)
    fail(c, cv.line(),
         cv.at("sink_degC") +
             ": missing; expected the sink temperature (sink_degC = 20.0 or "
             "sink_table = [[t_s, degC], ...])");
  core::TimeTable sink;
  sink.time = {0.0};
  sink.value = {temperature_c(c, *sd, cv.at("sink_degC"))};
  return sink;
}

/// One [[thermal.convection]] entry; a boundary group has at most one (`before`).
core::Convection read_convection(const Tab& cv, const Names& groups,
                                 const std::vector<core::Convection>& before) {
  const Ctx& c = *cv.ctx;
  cv.allow({"group", "h_W_m2K", "h_speed_gain_W_m2K", "speed_ref_rpm", "speed_exponent",
            "sink_degC", "sink_table"});
  core::Convection conv;
  conv.group = reference(cv, "group", groups, "boundary group");
  for (const auto& b : before)
    if (b.group == conv.group)
      fail_value(c, cv.need("group", ""), cv.at("group"), "already has a convection entry",
                 "merge the two into one");
  conv.h = number(cv, "h_W_m2K", Sign::non_negative, "heat transfer coefficient in W/(m^2 K)");
  conv.h_speed_gain = number_or(cv, "h_speed_gain_W_m2K", 0.0, Sign::non_negative);
  if (cv.get("h_speed_gain_W_m2K") && !cv.get("speed_ref_rpm"))
    fail(c, cv.line(),
         cv.at("speed_ref_rpm") +
             ": missing; expected the speed at which the gain applies, "
             "required with h_speed_gain_W_m2K");
  conv.speed_ref_rpm = number_or(cv, "speed_ref_rpm", conv.speed_ref_rpm, Sign::positive);
  conv.speed_exponent = number_or(cv, "speed_exponent", conv.speed_exponent, Sign::non_negative);
  conv.sink = convection_sink(cv);
  return conv;
}

// The keys of a [[thermal.heat_sources]] entry that each law uses.
const Names kSpeedLawKeys = {"power_ref_W", "ref_speed_rpm", "exponent"};
const Names kConstantLawKeys = {"power_ref_W"};
const Names kPalmgrenLawKeys = {"palmgren_f0", "palmgren_nu_cSt", "palmgren_dm", "palmgren_f1",
                                "palmgren_p1_N"};
const Names kFeedLawKeys = {"power_ref_W", "ref_feed_m_min", "ref_feed_m_s", "exponent"};

/// Every key of a heat source, in the order a near-miss suggestion considers them.
const Names kHeatSourceKeys = [] {
  Names all = {"name", "body", "law", "temperature_coefficient_per_K"};
  for (const Names* keys : {&kSpeedLawKeys, &kPalmgrenLawKeys})
    all.insert(all.end(), keys->begin(), keys->end());
  all.insert(all.end(), {"ref_feed_m_min", "ref_feed_m_s", "moving"});
  return all;
}();

/// A key that some law uses.
bool is_law_key(const std::string& key) {
  for (const Names* keys : {&kSpeedLawKeys, &kConstantLawKeys, &kPalmgrenLawKeys, &kFeedLawKeys})
    if (std::find(keys->begin(), keys->end(), key) != keys->end()) return true;
  return false;
}

const Names& law_keys(core::HeatSource::Law law) {
  using Law = core::HeatSource::Law;
  return law == Law::speed_power  ? kSpeedLawKeys
         : law == Law::constant   ? kConstantLawKeys
         : law == Law::feed_power ? kFeedLawKeys
                                  : kPalmgrenLawKeys;
}

/// Refuses a key of another law than the source's (a left-over would be silently ignored).
void check_law_keys(const Tab& h, core::HeatSource::Law law) {
  const Names& used = law_keys(law);
  const std::string& law_name = name_of(kLaws, law);
  for (auto&& [k, v] : *h.t) {
    const bool law_key = is_law_key(std::string(k.str()));
    if (law_key && std::find(used.begin(), used.end(), k.str()) == used.end())
      fail(*h.ctx, line_of(v),
           h.at(k.str()) + " = " + value_text(v) + ": not used by law = \"" + law_name +
               "\"; remove it or change the law");
  }
}

/// The parameters of `src.law`, read into `src`; feed_power needs a [feed_axis].
void read_law_parameters(const Tab& h, const CaseSpec& spec, core::HeatSource& src) {
  using Law = core::HeatSource::Law;
  if (src.law == Law::speed_power) {
    src.power_ref = number(h, "power_ref_W", Sign::non_negative, "heat at ref_speed_rpm in W");
    src.ref_speed_rpm = number(h, "ref_speed_rpm", Sign::positive);
    src.exponent = number_or(h, "exponent", 1.0, Sign::non_negative);
  } else if (src.law == Law::constant) {
    src.power_ref = number(h, "power_ref_W", Sign::non_negative, "heat in W");
  } else if (src.law == Law::feed_power) {
    if (spec.feed_axis.segments.empty())
      fail_value(*h.ctx, *h.get("law"), h.at("law"), "needs a [feed_axis] table",
                 "declare the axis's motion in [feed_axis]");
    src.power_ref = number(h, "power_ref_W", Sign::non_negative, "heat at ref_feed_m_min in W");
    src.ref_feed = feed_speed(h, "ref_feed", Sign::positive);
    src.exponent = number_or(h, "exponent", 1.0, Sign::non_negative);
  } else {
    src.palmgren_f0 = number(h, "palmgren_f0", Sign::positive, "bearing type factor f0");
    src.palmgren_nu_cSt =
        number(h, "palmgren_nu_cSt", Sign::positive, "lubricant kinematic viscosity in cSt");
    src.palmgren_dm = length(h, "palmgren_dm", Sign::positive, "bearing pitch diameter");
    src.palmgren_f1 = number(h, "palmgren_f1", Sign::non_negative, "load factor f1");
    src.palmgren_p1 = number(h, "palmgren_p1_N", Sign::non_negative, "equivalent load in N");
  }
}

/// A source's `moving = { window, offset }`: it heats a window that travels with the feed axis.
void read_moving_window(const Tab& h, const toml::node& mv, const CaseSpec& spec,
                        core::HeatSource& src) {
  const Ctx& c = *h.ctx;
  const Tab w = as_tab(c, mv, h.at("moving"), "an inline table { window, offset }");
  w.allow({"window", "offset"});
  if (spec.feed_axis.segments.empty())
    fail_value(c, mv, h.at("moving"), "needs a [feed_axis] table to move with");
  if (src.temperature_coefficient != 0)
    fail_value(c, mv, h.at("moving"), "cannot be combined with temperature_coefficient_per_K");
  src.window = length(w, "window", Sign::positive, "length of the heated part in length_unit");
  src.window_offset = number_or(w, "offset", 0.0) / c.length_divisor;
}

/// One [[thermal.heat_sources]] entry; its name is unique among the sources read before it.
core::HeatSource read_heat_source(const Tab& h, const CaseSpec& spec, const Names& bodies) {
  using Law = core::HeatSource::Law;
  h.allow(kHeatSourceKeys);
  core::HeatSource src;
  src.name = name(h, "name");
  unique(h, "name", src.name, names_of(spec.thermal.sources), "heat source");
  src.body = reference(h, "body", bodies, "body");
  src.law = choice_or<Law>(h, "law", Law::speed_power, kLaws);
  check_law_keys(h, src.law);
  read_law_parameters(h, spec, src);
  src.temperature_coefficient = number_or(h, "temperature_coefficient_per_K", 0.0);
  if (const auto* mv = h.get("moving")) read_moving_window(h, *mv, spec, src);
  return src;
}

/// One [[thermal.surface_flux]] entry.
core::SurfaceFlux read_surface_flux(const Tab& f, const Names& groups) {
  f.allow({"group", "flux_W_m2", "follows_speed", "ref_speed_rpm"});
  core::SurfaceFlux flux;
  flux.group = reference(f, "group", groups, "boundary group");
  flux.flux = number(f, "flux_W_m2", Sign::any, "heat flux into the body in W/m^2");
  flux.follows_speed = flag_or(f, "follows_speed", false);
  if (flux.follows_speed) {
    flux.ref_speed_rpm =
        number(f, "ref_speed_rpm", Sign::positive, "speed at which flux_W_m2 holds");
  } else if (const auto* r = f.get("ref_speed_rpm")) {
    fail_value(*f.ctx, *r, f.at("ref_speed_rpm"), "only used with follows_speed = true");
  }
  return flux;
}

void read_thermal(const Tab& root, CaseSpec& spec) {
  const toml::node* n = root.get("thermal");
  if (!n) return;
  const Tab t = as_tab(*root.ctx, *n, "thermal");
  t.allow({"initial_temperature_degC", "scheme", "step_s", "output_interval_s", "lumped_mass",
           "convection", "heat_sources", "surface_flux"});
  auto& th = spec.thermal;
  th.initial_temperature_c =
      temperature_or(t, "initial_temperature_degC", th.initial_temperature_c);
  th.scheme = choice_or<core::TimeScheme>(t, "scheme", th.scheme, kSchemes);
  th.step = number_or(t, "step_s", th.step, Sign::positive, "the time step in s");
  th.output_interval = number_or(t, "output_interval_s", th.output_interval, Sign::positive,
                                 "time between written samples in s");
  th.lumped_mass = flag_or(t, "lumped_mass", th.lumped_mass);

  const Names groups = names_of(spec.groups);
  const Names bodies = names_of(spec.bodies);
  each_table(t, "convection", [&](const Tab& cv, std::size_t) {
    th.convection.push_back(read_convection(cv, groups, th.convection));
  });
  each_table(t, "heat_sources", [&](const Tab& h, std::size_t) {
    th.sources.push_back(read_heat_source(h, spec, bodies));
  });
  each_table(t, "surface_flux",
             [&](const Tab& f, std::size_t) { th.fluxes.push_back(read_surface_flux(f, groups)); });
}

/// A step longer than the run leaves nothing to integrate (the default step included).
void check_step(const Tab& root, const CaseSpec& spec) {
  if (spec.thermal.step <= spec.duty_cycle.end) return;
  const std::string expected =
      "must not exceed the run, duty_cycle.end_s = " + number_text(spec.duty_cycle.end);
  const toml::node* th = root.get("thermal");
  const toml::node* s = th && th->is_table() ? th->as_table()->get("step_s") : nullptr;
  if (s) fail_value(*root.ctx, *s, "thermal.step_s", expected, "shorten the step");
  fail(*root.ctx, th ? line_of(*th) : 0,
       "thermal.step_s = " + number_text(spec.thermal.step) + " (the default): " + expected +
           "; set step_s in [thermal]");
}

/// The node of `key` in [thermal] when the case gives it, else the [thermal] table or the root.
const toml::node* thermal_key(const Tab& root, std::string_view key) {
  const toml::node* th = root.get("thermal");
  return th && th->is_table() ? th->as_table()->get(key) : nullptr;
}

/// duty_cycle.end_s / `interval` must not exceed `limit` (time steps, output times): every one
/// of them is allocated or solved.
void check_count(const Tab& root, const CaseSpec& spec, std::string_view key, double interval,
                 std::int64_t limit, const std::string& counted) {
  const double count = spec.duty_cycle.end / interval;
  if (count <= static_cast<double>(limit)) return;
  const std::string expected = "duty_cycle.end_s = " + number_text(spec.duty_cycle.end) +
                               " would need " + number_text(std::ceil(count)) + " " + counted +
                               ", more than the limit of " + std::to_string(limit);
  const std::string hint = "lengthen " + std::string(key) + " or shorten the run";
  const std::string path = "thermal." + std::string(key);
  if (const toml::node* n = thermal_key(root, key)) fail_value(*root.ctx, *n, path, expected, hint);
  const toml::node* end = root.get("duty_cycle")->as_table()->get("end_s");
  fail_value(*root.ctx, *end, "duty_cycle.end_s",
             "would need " + number_text(std::ceil(count)) + " " + counted + " of " + path + " = " +
                 number_text(interval) + " s (the default), more than the limit of " +
                 std::to_string(limit),
             "shorten the run or set " + std::string(key) + " in [thermal]");
}

/// [feed_axis]: segments = [{ start_s, from, to, feed_m_min } | { start_s, position }, ...].
void read_feed_axis(const Tab& root, CaseSpec& spec) {
  const toml::node* n = root.get("feed_axis");
  if (!n) return;
  const Tab f = as_tab(*root.ctx, *n, "feed_axis");
  const Ctx& c = *f.ctx;
  f.allow({"name", "direction", "segments"});
  auto& ax = spec.feed_axis;
  ax.name = f.get("name") ? name(f, "name") : "X";
  ax.direction = choice_or<int>(f, "direction", 0, {{"x", 0}, {"y", 1}, {"z", 2}});
  const auto& sn = f.need("segments", "segments = [{ start_s, from, to, feed_m_min }, ...]");
  each_table(f, "segments", [&](const Tab& s, std::size_t i) {
    s.allow({"start_s", "from", "to", "feed_m_min", "feed_m_s", "position"});
    core::FeedAxis::Segment seg;
    const auto& st = s.need("start_s", "a time in s");
    seg.start = as_number(c, st, s.at("start_s"));
    if (i == 0 && seg.start != 0)
      fail_value(c, st, s.at("start_s"), "the first segment must start at 0");
    if (i > 0 && !(seg.start > ax.segments.back().start))
      fail_value(c, st, s.at("start_s"),
                 "must exceed the previous start " + number_text(ax.segments.back().start),
                 "segments must be in ascending time order");
    if (!(seg.start < spec.duty_cycle.end))
      fail_value(c, st, s.at("start_s"),
                 "must be before duty_cycle.end_s = " + number_text(spec.duty_cycle.end));
    if (const auto* pos = s.get("position")) {
      for (const char* k : {"from", "to", "feed_m_min", "feed_m_s"})
        if (const auto* x = s.get(k))
          fail_value(c, *x, s.at(k), "not used with position (a standing axis)");
      seg.from = seg.to = checked(c, *pos, s.at("position"), Sign::any, "") / c.length_divisor;
    } else {
      seg.from = number(s, "from", Sign::any, "where the stroke starts, in length_unit") /
                 c.length_divisor;
      seg.to =
          number(s, "to", Sign::any, "where the stroke turns, in length_unit") / c.length_divisor;
      seg.feed = feed_speed(s, "feed", Sign::non_negative);
    }
    ax.segments.push_back(seg);
  });
  if (ax.segments.empty()) fail_value(c, sn, f.at("segments"), "must hold at least one segment");
}

/// mechanical.targets, axis_points and axis_polynomial_degree.
void read_axis_keys(const Tab& m, CaseSpec& spec) {
  const Ctx& c = *m.ctx;
  auto& me = spec.mechanical;
  if (const auto* t = m.get("targets")) {
    const auto& a = as_array(c, *t, m.at("targets"), "an array of directions [\"dy\", \"dz\"]");
    if (a.empty()) fail_value(c, *t, m.at("targets"), "must name at least one direction");
    me.targets.clear();
    for (std::size_t i = 0; i < a.size(); ++i) {
      const std::string p = m.at("targets") + "[" + std::to_string(i) + "]";
      const std::string d =
          choice<std::string>(c, a[i], p, {{"dx", "dx"}, {"dy", "dy"}, {"dz", "dz"}});
      if (std::find(me.targets.begin(), me.targets.end(), d) != me.targets.end())
        fail_value(c, a[i], p, "listed twice");
      me.targets.push_back(d);
    }
  }
  if (const auto* a = m.get("axis_points")) {
    if (spec.feed_axis.segments.empty())
      fail_value(c, *a, m.at("axis_points"), "needs a [feed_axis] table (the axis they lie along)");
    for (int i : references(c, *a, m.at("axis_points"), point_ids(spec), "point"))
      me.axis_points.push_back(spec.points[i].id);
  }
  if (const auto* d = m.get("axis_polynomial_degree")) {
    const auto v = integer(c, *d, m.at("axis_polynomial_degree"));
    if (v < 0 || v > 9) fail_value(c, *d, m.at("axis_polynomial_degree"), "must lie in [0, 9]");
    me.axis_polynomial_degree = static_cast<int>(v);
  }
  if (!me.axis_points.empty() &&
      static_cast<int>(me.axis_points.size()) <= me.axis_polynomial_degree)
    fail_value(c, *m.get("axis_points"), m.at("axis_points"),
               "needs more points (" + std::to_string(me.axis_points.size()) +
                   ") than the polynomial degree " + std::to_string(me.axis_polynomial_degree),
               "add points or lower axis_polynomial_degree");
}

void read_mechanical(const Tab& root, CaseSpec& spec) {
  auto& me = spec.mechanical;
  const toml::node* n = root.get("mechanical");
  if (!n) {
    if (me.enabled)
      fail(*root.ctx, 0,
           "mechanical: missing; expected a [mechanical] table with fixed = [group names], or "
           "enabled = false");
    return;
  }
  const Tab m = as_tab(*root.ctx, *n, "mechanical");
  const Ctx& c = *m.ctx;
  m.allow({"enabled", "reference_temperature_degC", "fixed", "point_supports", "tcp", "probes",
           "targets", "axis_points", "axis_polynomial_degree"});
  me.enabled = flag_or(m, "enabled", me.enabled);
  me.reference_temperature_c =
      temperature_or(m, "reference_temperature_degC", me.reference_temperature_c);
  if (const auto* f = m.get("fixed"))
    me.fixed_groups = references(c, *f, m.at("fixed"), names_of(spec.groups), "boundary group");
  const Names ids = point_ids(spec);
  Names supported;
  each_table(m, "point_supports", [&](const Tab& s, std::size_t) {
    s.allow({"point", "fixed"});
    core::PointSupport support;
    support.point = spec.points[reference(s, "point", ids, "point")].id;
    unique(s, "point", support.point, supported, "support on the point");
    supported.push_back(support.point);
    if (const auto* f = s.get("fixed")) {
      support.fixed = {false, false, false};
      const auto& a =
          as_array(c, *f, s.at("fixed"), "an array of directions [\"x\", \"y\", \"z\"]");
      if (a.empty()) fail_value(c, *f, s.at("fixed"), "must name at least one direction");
      for (std::size_t i = 0; i < a.size(); ++i) {
        const std::string p = s.at("fixed") + "[" + std::to_string(i) + "]";
        const int d = choice<int>(c, a[i], p, {{"x", 0}, {"y", 1}, {"z", 2}});
        if (support.fixed[d]) fail_value(c, a[i], p, "listed twice");
        support.fixed[d] = true;
      }
    }
    me.point_supports.push_back(support);
  });
  if (me.enabled && me.fixed_groups.empty() && me.point_supports.empty()) {
    if (const auto* f = m.get("fixed"))
      fail_value(c, *f, m.at("fixed"), "must name at least one boundary group",
                 "without a support the body can move freely (or give point_supports)");
    fail(c, m.line(),
         m.at("fixed") +
             ": missing; expected the boundary groups fixed in all directions "
             "(or point_supports, or enabled = false)");
  }
  if (const auto* t = m.get("tcp"))
    me.tcp_point = spec.points[reference(c, *t, m.at("tcp"), ids, "point")].id;
  if (const auto* p = m.get("probes")) {
    const auto idx = references(c, *p, m.at("probes"), ids, "point");
    if (!idx.empty() && idx.size() != 2)
      fail_value(c, *p, m.at("probes"), "expected two point ids [z1, z2]");
    for (int i : idx) me.probe_points.push_back(spec.points[i].id);
  }
  read_axis_keys(m, spec);
}

void read_outputs(const Tab& root, CaseSpec& spec) {
  const toml::node* n = root.get("outputs");
  if (!n) return;
  const Tab o = as_tab(*root.ctx, *n, "outputs");
  o.allow({"plot_points", "fields", "fields_interval_s"});
  if (const auto* p = o.get("plot_points")) {
    for (int i : references(*o.ctx, *p, o.at("plot_points"), point_ids(spec), "point"))
      spec.outputs.plot_points.push_back(spec.points[i].id);
  }
  spec.outputs.fields = flag_or(o, "fields", spec.outputs.fields);
  spec.outputs.fields_interval = number_or(o, "fields_interval_s", spec.outputs.fields_interval,
                                           Sign::positive, "time between field snapshots in s");
}

/// [placement]: which candidates the sensors are chosen from. Read after [mechanical], whose
/// TCP, probe and axis points cannot be sensor positions.
void read_placement(const Tab& root, CaseSpec& spec) {
  using Candidates = core::PlacementSpec::Candidates;
  const toml::node* n = root.get("placement");
  if (!n) return;
  const Tab p = as_tab(*root.ctx, *n, "placement");
  const Ctx& c = *p.ctx;
  p.allow({"candidates", "points", "bodies", "groups", "max_candidates"});
  auto& pl = spec.placement;
  pl.candidates = choice_or<Candidates>(p, "candidates", pl.candidates, kCandidateKinds);
  const bool surface = pl.surface();
  const auto& me = spec.mechanical;
  if (const auto* a = p.get("points")) {
    const auto idx = references(c, *a, p.at("points"), point_ids(spec), "point");
    for (std::size_t i = 0; i < idx.size(); ++i) {
      const std::string& id = spec.points[idx[i]].id;
      const auto listed = [&](const Names& ids) {
        return std::find(ids.begin(), ids.end(), id) != ids.end();
      };
      const char* role = id == me.tcp_point        ? "the TCP"
                         : listed(me.probe_points) ? "a probe point"
                         : listed(me.axis_points)  ? "a feed-axis measurement point"
                                                   : nullptr;
      if (role)
        fail_value(c, (*a->as_array())[i], p.at("points") + "[" + std::to_string(i) + "]",
                   std::string("is ") + role + ", not a sensor position");
      pl.points.push_back(id);
    }
  }
  // Keys that only mean something for surface candidates.
  for (const char* key : {"bodies", "groups", "max_candidates"})
    if (!surface && p.get(key))
      fail_value(c, *p.get(key), p.at(key), "only used with candidates = \"surface\"",
                 "add candidates = \"surface\" or remove the key");
  if (const auto* b = p.get("bodies"))
    pl.bodies = references(c, *b, p.at("bodies"), names_of(spec.bodies), "body");
  if (const auto* g = p.get("groups"))
    pl.groups = references(c, *g, p.at("groups"), names_of(spec.groups), "boundary group");
  if (surface && pl.bodies.empty() && pl.groups.empty())
    fail_value(c, p.need("candidates", ""), p.at("candidates"),
               "needs bodies = [body names] or groups = [boundary group names] in placement",
               "the surface vertices of those bodies or groups become the candidates");
  if (const auto* m = p.get("max_candidates")) {
    const auto v = integer(c, *m, p.at("max_candidates"));
    if (v < 0 || v > 10'000'000)
      fail_value(c, *m, p.at("max_candidates"), "must lie in [0, 10000000]",
                 "0 keeps every surface vertex");
    pl.max_candidates = static_cast<int>(v);
  }
}

CaseSpec case_from_root(const toml::table& root, Ctx& ctx, const fs::path& file) {
  const Tab r{&ctx, &root, ""};
  r.allow({"case", "geometry", "materials", "bodies", "mesh", "boundary", "points", "duty_cycle",
           "thermal", "mechanical", "outputs", "feed_axis", "placement"});
  CaseSpec spec;
  spec.source = file;
  read_header(r, spec);
  const Tab g = as_tab(ctx, r.need("geometry", "a [geometry] table with length_unit"), "geometry");
  g.allow({"length_unit"});
  ctx.length_divisor =
      unit_divisor(ctx, g.need("length_unit", "\"m\" or \"mm\""), g.at("length_unit"));
  read_materials(r, spec);
  read_bodies(r, spec);
  read_mesh(r, spec);
  read_boundary(r, spec);
  read_points(r, spec);
  read_duty_cycle(r, spec);
  read_feed_axis(r, spec);
  read_thermal(r, spec);
  check_step(r, spec);
  check_count(r, spec, "step_s", spec.thermal.step, core::limits::kTimeSteps, "time steps");
  check_count(r, spec, "output_interval_s", spec.thermal.output_interval,
              core::limits::kOutputTimes, "output times");
  read_mechanical(r, spec);
  read_outputs(r, spec);
  read_placement(r, spec);
  return spec;
}

// ---------------------------------------------------------------------------------------------
// Writer.

std::string vec_text(const auto& v) {
  std::string s = "[";
  for (Eigen::Index i = 0; i < v.size(); ++i) s += (i ? ", " : "") + number_text(v[i]);
  return s + "]";
}

std::string names_text(const std::vector<int>& idx, const Names& names) {
  std::string s = "[";
  for (std::size_t i = 0; i < idx.size(); ++i) s += (i ? ", " : "") + toml_string(names.at(idx[i]));
  return s + "]";
}

std::string strings_text(const Names& names) {
  std::string s = "[";
  for (std::size_t i = 0; i < names.size(); ++i) s += (i ? ", " : "") + toml_string(names[i]);
  return s + "]";
}

std::string primitive_text(const core::Primitive& p) {
  using K = core::Primitive::Kind;
  const std::string z = "z = [" + number_text(p.z_min) + ", " + number_text(p.z_max) + "]";
  switch (p.kind) {
    case K::box:
      return "{ box = { min = " + vec_text(p.min) + ", max = " + vec_text(p.max) + " } }";
    case K::cylinder:
      return "{ cylinder = { axis = " + vec_text(p.axis) + ", radius = " + number_text(p.radius) +
             ", " + z + " } }";
    case K::annulus:
      return "{ annulus = { axis = " + vec_text(p.axis) +
             ", inner_radius = " + number_text(p.inner_radius) +
             ", outer_radius = " + number_text(p.radius) + ", " + z + " } }";
    case K::surface_file:
      break;
  }
  if (p.file_scale != 1.0 && p.file_scale != 1e-3)
    throw CaseError(p.where + ".surface: file_scale = " + number_text(p.file_scale) +
                    ": cannot be written as a length unit; expected 1 (m) or 0.001 (mm)");
  return "{ surface = { file = " + toml_string(fs::absolute(p.file).lexically_normal().string()) +
         ", unit = " + toml_string(p.file_scale == 1.0 ? "m" : "mm") + " } }";
}

std::string primitives_text(const std::vector<core::Primitive>& ps) {
  if (ps.empty()) return "[]";
  std::string s = "[\n";
  for (const auto& p : ps) s += "  " + primitive_text(p) + ",\n";
  return s + "]";
}

std::string selector_text(const core::FaceSelector& s, const Names& bodies) {
  using Side = core::FaceSelector::Side;
  std::string t = "{ bodies = " + names_text(s.bodies, bodies) +
                  ", side = " + toml_string(name_of(kSides, s.side));
  if (s.side == Side::interface) t += ", other_bodies = " + names_text(s.other_bodies, bodies);
  if (s.plane) {
    t += ", plane = { normal = " + vec_text(s.plane->head<3>()) +
         ", offset = " + number_text((*s.plane)[3]) + " }";
  }
  if (s.on_cylinder) {
    t += ", on_cylinder = { axis = " + vec_text(s.on_cylinder->axis) +
         ", radius = " + number_text(s.on_cylinder->radius) + " }";
  }
  if (s.within_min && s.within_max) {
    t += ", within = { min = " + vec_text(*s.within_min) + ", max = " + vec_text(*s.within_max) +
         " }";
  }
  return t + " }";
}

/// [case], [geometry] (always m), the materials, the bodies, [mesh] and the boundary groups.
std::string model_toml(const CaseSpec& spec, const Names& bodies) {
  std::ostringstream o;
  o << "# Resolved case: SI units, every default explicit. Read from "
    << fs::absolute(spec.source).lexically_normal().string()
    << "\n\n[case]\nname = " << toml_string(spec.name)
    << "\nmachine = " << toml_string(spec.machine) << "\nseed = " << spec.seed
    << "\n\n[geometry]\nlength_unit = \"m\"\n";
  for (const auto& m : spec.materials) {
    o << "\n[materials." << key_text(m.name) << "]\ndensity_kg_m3 = " << number_text(m.density)
      << "\nspecific_heat_J_kgK = " << number_text(m.specific_heat)
      << "\nconductivity_W_mK = " << number_text(m.conductivity)
      << "\nyoungs_modulus_Pa = " << number_text(m.youngs_modulus)
      << "\npoisson_ratio = " << number_text(m.poisson_ratio)
      << "\nexpansion_per_K = " << number_text(m.expansion) << "\n";
  }
  for (const auto& b : spec.bodies) {
    o << "\n[[bodies]]\nname = " << toml_string(b.name)
      << "\nmaterial = " << toml_string(spec.materials.at(b.material).name)
      << "\nmax_edge = " << number_text(b.max_edge) << "\nadd = " << primitives_text(b.add)
      << "\nsubtract = " << primitives_text(b.subtract) << "\n";
  }
  o << "\n[mesh]\norder = " << spec.mesh.order
    << "\ncircle_segments = " << spec.mesh.circle_segments
    << "\nradius_edge_ratio = " << number_text(spec.mesh.radius_edge_ratio)
    << "\nmin_dihedral_deg = " << number_text(spec.mesh.min_dihedral_deg)
    << "\nmax_tets = " << number_text(spec.mesh.max_tets)
    << "\ntime_limit_s = " << number_text(spec.mesh.time_limit_s)
    << "\nmemory_limit_GB = " << number_text(spec.mesh.memory_limit_GB) << "\n";
  for (const auto& g : spec.groups) {
    o << "\n[[boundary]]\nname = " << toml_string(g.name)
      << "\nrest = " << (g.rest ? "true" : "false") << "\nselect = [\n";
    for (const auto& s : g.select) o << "  " << selector_text(s, bodies) << ",\n";
    o << "]\n";
  }
  return o.str();
}

/// One [[thermal.convection]] entry; a constant sink is written as sink_degC.
std::string convection_toml(const core::Convection& c, const Names& groups) {
  std::ostringstream o;
  o << "\n[[thermal.convection]]\ngroup = " << toml_string(groups.at(c.group))
    << "\nh_W_m2K = " << number_text(c.h)
    << "\nh_speed_gain_W_m2K = " << number_text(c.h_speed_gain)
    << "\nspeed_ref_rpm = " << number_text(c.speed_ref_rpm)
    << "\nspeed_exponent = " << number_text(c.speed_exponent) << "\n";
  if (c.sink.time.size() == 1 && c.sink.time[0] == 0) {
    o << "sink_degC = " << number_text(c.sink.value.at(0)) << "\n";
  } else {
    o << "sink_table = [";
    for (std::size_t i = 0; i < c.sink.time.size(); ++i)
      o << (i ? ", [" : "[") << number_text(c.sink.time[i]) << ", "
        << number_text(c.sink.value.at(i)) << "]";
    o << "]\n";
  }
  return o.str();
}

/// One [[thermal.heat_sources]] entry with exactly the keys its law uses.
std::string heat_source_toml(const core::HeatSource& s, const Names& bodies) {
  using Law = core::HeatSource::Law;
  std::ostringstream o;
  o << "\n[[thermal.heat_sources]]\nname = " << toml_string(s.name)
    << "\nbody = " << toml_string(bodies.at(s.body))
    << "\nlaw = " << toml_string(name_of(kLaws, s.law)) << "\n";
  if (s.law == Law::speed_power) {
    o << "power_ref_W = " << number_text(s.power_ref)
      << "\nref_speed_rpm = " << number_text(s.ref_speed_rpm)
      << "\nexponent = " << number_text(s.exponent) << "\n";
  } else if (s.law == Law::constant) {
    o << "power_ref_W = " << number_text(s.power_ref) << "\n";
  } else if (s.law == Law::feed_power) {
    o << "power_ref_W = " << number_text(s.power_ref)
      << "\nref_feed_m_s = " << number_text(s.ref_feed)
      << "\nexponent = " << number_text(s.exponent) << "\n";
  } else {
    o << "palmgren_f0 = " << number_text(s.palmgren_f0)
      << "\npalmgren_nu_cSt = " << number_text(s.palmgren_nu_cSt)
      << "\npalmgren_dm = " << number_text(s.palmgren_dm)
      << "\npalmgren_f1 = " << number_text(s.palmgren_f1)
      << "\npalmgren_p1_N = " << number_text(s.palmgren_p1) << "\n";
  }
  o << "temperature_coefficient_per_K = " << number_text(s.temperature_coefficient) << "\n";
  if (s.window > 0)
    o << "moving = { window = " << number_text(s.window)
      << ", offset = " << number_text(s.window_offset) << " }\n";
  return o.str();
}

/// [thermal] with its convection, heat sources and surface fluxes.
std::string thermal_toml(const core::ThermalSpec& th, const Names& bodies, const Names& groups) {
  std::ostringstream o;
  o << "\n[thermal]\ninitial_temperature_degC = " << number_text(th.initial_temperature_c)
    << "\nscheme = " << toml_string(name_of(kSchemes, th.scheme))
    << "\nstep_s = " << number_text(th.step)
    << "\noutput_interval_s = " << number_text(th.output_interval)
    << "\nlumped_mass = " << (th.lumped_mass ? "true" : "false") << "\n";
  for (const auto& c : th.convection) o << convection_toml(c, groups);
  for (const auto& s : th.sources) o << heat_source_toml(s, bodies);
  for (const auto& f : th.fluxes) {
    o << "\n[[thermal.surface_flux]]\ngroup = " << toml_string(groups.at(f.group))
      << "\nflux_W_m2 = " << number_text(f.flux)
      << "\nfollows_speed = " << (f.follows_speed ? "true" : "false") << "\n";
    if (f.follows_speed) o << "ref_speed_rpm = " << number_text(f.ref_speed_rpm) << "\n";
  }
  return o.str();
}

/// [duty_cycle] with its segments listed, and [feed_axis] when there is one.
std::string motion_toml(const CaseSpec& spec) {
  std::ostringstream o;
  o << "\n[duty_cycle]\nend_s = " << number_text(spec.duty_cycle.end) << "\nsegments = [\n";
  for (const auto& s : spec.duty_cycle.segments)
    o << "  { start_s = " << number_text(s.start) << ", speed_rpm = " << number_text(s.speed_rpm)
      << " },\n";
  o << "]\n";
  if (!spec.feed_axis.segments.empty()) {
    const auto& ax = spec.feed_axis;
    o << "\n[feed_axis]\nname = " << toml_string(ax.name) << "\ndirection = \""
      << "xyz"[ax.direction] << "\"\nsegments = [\n";
    for (const auto& s : ax.segments)
      o << "  { start_s = " << number_text(s.start) << ", from = " << number_text(s.from)
        << ", to = " << number_text(s.to) << ", feed_m_s = " << number_text(s.feed) << " },\n";
    o << "]\n";
  }
  return o.str();
}

std::string mechanical_toml(const core::MechanicalSpec& me, const Names& groups) {
  std::ostringstream o;
  o << "\n[mechanical]\nenabled = " << (me.enabled ? "true" : "false")
    << "\nreference_temperature_degC = " << number_text(me.reference_temperature_c)
    << "\nfixed = " << names_text(me.fixed_groups, groups) << "\npoint_supports = [";
  for (std::size_t i = 0; i < me.point_supports.size(); ++i) {
    const auto& ps = me.point_supports[i];
    Names dirs;
    for (int d = 0; d < 3; ++d)
      if (ps.fixed[d]) dirs.push_back(std::string(1, "xyz"[d]));
    o << (i ? ", " : "") << "{ point = " << toml_string(ps.point)
      << ", fixed = " << strings_text(dirs) << " }";
  }
  o << "]\n";
  if (!me.tcp_point.empty()) o << "tcp = " << toml_string(me.tcp_point) << "\n";
  o << "probes = " << strings_text(me.probe_points) << "\n";
  o << "targets = " << strings_text(me.targets) << "\n";
  if (!me.axis_points.empty())
    o << "axis_points = " << strings_text(me.axis_points)
      << "\naxis_polynomial_degree = " << me.axis_polynomial_degree << "\n";
  return o.str();
}

/// [outputs], [placement] and the named [points].
std::string outputs_toml(const CaseSpec& spec, const Names& bodies, const Names& groups) {
  std::ostringstream o;
  o << "\n[outputs]\nplot_points = " << strings_text(spec.outputs.plot_points)
    << "\nfields = " << (spec.outputs.fields ? "true" : "false")
    << "\nfields_interval_s = " << number_text(spec.outputs.fields_interval) << "\n";
  const auto& pl = spec.placement;
  o << "\n[placement]\ncandidates = " << toml_string(name_of(kCandidateKinds, pl.candidates))
    << "\npoints = " << strings_text(pl.points) << "\n";
  if (pl.surface())
    o << "bodies = " << names_text(pl.bodies, bodies)
      << "\ngroups = " << names_text(pl.groups, groups)
      << "\nmax_candidates = " << pl.max_candidates << "\n";
  o << "\n[points]\nlist = [\n";
  for (const auto& p : spec.points) {
    o << "  { id = " << toml_string(p.id) << ", position = " << vec_text(p.position);
    if (p.on_group >= 0) o << ", on = " << toml_string(groups.at(p.on_group));
    o << " },\n";
  }
  o << "]\n";
  return o.str();
}

}  // namespace

CaseSpec case_from_toml(std::string_view text, const fs::path& file) {
  Ctx ctx;
  ctx.file = file.string();
  ctx.dir = file.parent_path();
  toml::table root;
  try {
    root = toml::parse(text, std::string_view(ctx.file));
  } catch (const toml::parse_error& e) {
    fail(ctx, static_cast<int>(e.source().begin.line),
         "not valid TOML: " + std::string(e.description()));
  }
  return case_from_root(root, ctx, file);
}

CaseSpec read_case(const fs::path& file) {
  using core::limits::kCaseFileBytes;
  std::optional<std::string> text;
  try {
    text = core::limits::file_text_up_to(file, kCaseFileBytes);
  } catch (const core::IoError&) {
    throw core::IoError(file.string() + ": cannot open or read the case file");
  }
  if (!text)
    throw CaseError(file.string() + ": holds more than " +
                    core::limits::bytes_text(kCaseFileBytes) +
                    ", the limit for a case file; is it the case file (a TOML text)?");
  return case_from_toml(*text, file);
}

CaseSpec with_duty_cycle_csv(const CaseSpec& spec, const fs::path& file,
                             std::optional<double> end_s) {
  using core::limits::kDutyCycleFileBytes;
  const std::optional<std::string> bytes = core::limits::file_text_up_to(file, kDutyCycleFileBytes);
  if (!bytes)
    throw CaseError(file.string() + ": holds more than " +
                    core::limits::bytes_text(kDutyCycleFileBytes) +
                    ", the limit for a duty-cycle CSV; a row per speed change is enough");
  CaseSpec out = spec;
  out.duty_cycle.segments = parse_duty_cycle_csv(*bytes, file, " (--duty-cycle)");
  out.duty_cycle.csv = fs::absolute(file).lexically_normal();
  if (end_s) out.duty_cycle.end = *end_s;
  const double end = out.duty_cycle.end, last = out.duty_cycle.segments.back().start;
  const std::string end_from = end_s ? "--end-s" : "duty_cycle.end_s of " + spec.source.string();
  if (!(std::isfinite(end) && end > last))
    throw CaseError(file.string() + ": the last row starts at " + number_text(last) +
                    " s, not before the run's end " + number_text(end) + " s (" + end_from +
                    "); hint: give --end-s beyond the last row");
  if (end / out.thermal.step > static_cast<double>(core::limits::kTimeSteps) ||
      end / out.thermal.output_interval > static_cast<double>(core::limits::kOutputTimes))
    throw CaseError(end_from + " = " + number_text(end) + " s: more than " +
                    std::to_string(core::limits::kTimeSteps) + " steps of " +
                    number_text(out.thermal.step) + " s or " +
                    std::to_string(core::limits::kOutputTimes) + " output times of " +
                    number_text(out.thermal.output_interval) + " s; hint: a shorter run");
  return out;
}

std::vector<fs::path> case_input_files(const CaseSpec& spec) {
  std::vector<fs::path> files{spec.source};
  for (const auto& body : spec.bodies)
    for (const auto* prims : {&body.add, &body.subtract})
      for (const auto& p : *prims)
        if (p.kind == core::Primitive::Kind::surface_file) files.push_back(p.file);
  if (!spec.duty_cycle.csv.empty()) files.push_back(spec.duty_cycle.csv);
  return files;
}

std::string resolved_case_toml(const CaseSpec& spec) {
  const Names bodies = names_of(spec.bodies);
  const Names groups = names_of(spec.groups);
  // One section after the other, so that the first section that cannot be written is the one
  // reported.
  std::string out = model_toml(spec, bodies);
  out += thermal_toml(spec.thermal, bodies, groups);
  out += motion_toml(spec);
  out += mechanical_toml(spec.mechanical, groups);
  out += outputs_toml(spec, bodies, groups);
  return out;
}

}  // namespace tt::io
