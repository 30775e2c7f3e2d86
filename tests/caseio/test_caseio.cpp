// Case reader: SB-1 parses into the spec's numbers, mm and m give the same SI spec, the resolved
// TOML reads back to the same spec, and every kind of bad input is reported with file, line and
// key path.
#include <gtest/gtest.h>
#include <unistd.h>

#include <array>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <string>

#include "core/errors.hpp"
#include "io/case_reader.hpp"

namespace fs = std::filesystem;
using tt::core::CaseError;
using tt::core::CaseSpec;
using tt::io::read_case;
using tt::io::resolved_case_toml;

namespace {

const fs::path sb1_file = fs::path(TT_SOURCE_DIR) / "cases" / "sb1.toml";
const fs::path sb1_mm_file = fs::path(TT_SOURCE_DIR) / "tests" / "caseio" / "data" / "sb1_mm.toml";

/// A scratch folder per test, removed afterwards.
class CaseFiles : public ::testing::Test {
 protected:
  void SetUp() override {
    std::string name = ::testing::UnitTest::GetInstance()->current_test_info()->name();
    for (char& c : name)
      if (c == '/') c = '_';
    dir_ = fs::temp_directory_path() / ("tt_caseio_" + std::to_string(::getpid()) + "_" + name);
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }

  fs::path write(const std::string& file_name, const std::string& text) const {
    const fs::path p = dir_ / file_name;
    std::ofstream(p) << text;
    return p;
  }
  fs::path dir_;
};

void expect_near_rel(double a, double b, double tol, const std::string& what) {
  if (tol == 0) {
    EXPECT_EQ(a, b) << what;
  } else {
    EXPECT_NEAR(a, b, tol * std::max(1.0, std::abs(b))) << what;
  }
}

template <class V>
void expect_vec(const V& a, const V& b, double tol, const std::string& what) {
  ASSERT_EQ(a.size(), b.size()) << what;
  for (Eigen::Index i = 0; i < a.size(); ++i) expect_near_rel(a[i], b[i], tol, what);
}

void expect_same_primitives(const std::vector<tt::core::Primitive>& a,
                            const std::vector<tt::core::Primitive>& b, double tol) {
  ASSERT_EQ(a.size(), b.size());
  for (std::size_t i = 0; i < a.size(); ++i) {
    const std::string w = a[i].where;
    EXPECT_EQ(a[i].kind, b[i].kind) << w;
    expect_vec(a[i].min, b[i].min, tol, w + " min");
    expect_vec(a[i].max, b[i].max, tol, w + " max");
    expect_vec(a[i].axis, b[i].axis, tol, w + " axis");
    expect_near_rel(a[i].radius, b[i].radius, tol, w + " radius");
    expect_near_rel(a[i].inner_radius, b[i].inner_radius, tol, w + " inner_radius");
    expect_near_rel(a[i].z_min, b[i].z_min, tol, w + " z_min");
    expect_near_rel(a[i].z_max, b[i].z_max, tol, w + " z_max");
    EXPECT_EQ(a[i].file, b[i].file) << w;
    EXPECT_EQ(a[i].file_scale, b[i].file_scale) << w;
    EXPECT_EQ(a[i].where, b[i].where);
  }
}

/// Every field of the spec except `source`; doubles exactly when tol = 0.
void expect_same(const CaseSpec& a, const CaseSpec& b, double tol = 0) {
  EXPECT_EQ(a.name, b.name);
  EXPECT_EQ(a.machine, b.machine);
  EXPECT_EQ(a.seed, b.seed);
  ASSERT_EQ(a.materials.size(), b.materials.size());
  for (std::size_t i = 0; i < a.materials.size(); ++i) {
    const auto &x = a.materials[i], &y = b.materials[i];
    EXPECT_EQ(x.name, y.name);
    EXPECT_EQ(x.density, y.density);
    EXPECT_EQ(x.specific_heat, y.specific_heat);
    EXPECT_EQ(x.conductivity, y.conductivity);
    EXPECT_EQ(x.youngs_modulus, y.youngs_modulus);
    EXPECT_EQ(x.poisson_ratio, y.poisson_ratio);
    EXPECT_EQ(x.expansion, y.expansion);
  }
  ASSERT_EQ(a.bodies.size(), b.bodies.size());
  for (std::size_t i = 0; i < a.bodies.size(); ++i) {
    EXPECT_EQ(a.bodies[i].name, b.bodies[i].name);
    EXPECT_EQ(a.bodies[i].material, b.bodies[i].material);
    expect_near_rel(a.bodies[i].max_edge, b.bodies[i].max_edge, tol, "max_edge");
    expect_same_primitives(a.bodies[i].add, b.bodies[i].add, tol);
    expect_same_primitives(a.bodies[i].subtract, b.bodies[i].subtract, tol);
  }
  ASSERT_EQ(a.groups.size(), b.groups.size());
  for (std::size_t i = 0; i < a.groups.size(); ++i) {
    const auto &x = a.groups[i], &y = b.groups[i];
    EXPECT_EQ(x.name, y.name);
    EXPECT_EQ(x.rest, y.rest);
    ASSERT_EQ(x.select.size(), y.select.size());
    for (std::size_t j = 0; j < x.select.size(); ++j) {
      const auto &s = x.select[j], &t = y.select[j];
      EXPECT_EQ(s.bodies, t.bodies);
      EXPECT_EQ(s.side, t.side);
      EXPECT_EQ(s.other_bodies, t.other_bodies);
      ASSERT_EQ(s.plane.has_value(), t.plane.has_value());
      if (s.plane) expect_vec(*s.plane, *t.plane, tol, x.name + " plane");
      ASSERT_EQ(s.on_cylinder.has_value(), t.on_cylinder.has_value());
      if (s.on_cylinder) {
        expect_vec(s.on_cylinder->axis, t.on_cylinder->axis, tol, x.name + " cylinder axis");
        expect_near_rel(s.on_cylinder->radius, t.on_cylinder->radius, tol, x.name + " radius");
      }
      ASSERT_EQ(s.within_min.has_value(), t.within_min.has_value());
      ASSERT_EQ(s.within_max.has_value(), t.within_max.has_value());
      if (s.within_min) expect_vec(*s.within_min, *t.within_min, tol, x.name + " within");
      if (s.within_max) expect_vec(*s.within_max, *t.within_max, tol, x.name + " within");
    }
  }
  ASSERT_EQ(a.points.size(), b.points.size());
  for (std::size_t i = 0; i < a.points.size(); ++i) {
    EXPECT_EQ(a.points[i].id, b.points[i].id);
    expect_vec(a.points[i].position, b.points[i].position, tol, a.points[i].id);
    EXPECT_EQ(a.points[i].on_group, b.points[i].on_group);
  }
  EXPECT_EQ(a.mesh.order, b.mesh.order);
  EXPECT_EQ(a.mesh.circle_segments, b.mesh.circle_segments);
  EXPECT_EQ(a.mesh.radius_edge_ratio, b.mesh.radius_edge_ratio);
  EXPECT_EQ(a.mesh.min_dihedral_deg, b.mesh.min_dihedral_deg);
  EXPECT_EQ(a.mesh.max_tets, b.mesh.max_tets);
  EXPECT_EQ(a.mesh.time_limit_s, b.mesh.time_limit_s);
  EXPECT_EQ(a.mesh.memory_limit_GB, b.mesh.memory_limit_GB);
  EXPECT_EQ(a.duty_cycle.end, b.duty_cycle.end);
  ASSERT_EQ(a.duty_cycle.segments.size(), b.duty_cycle.segments.size());
  for (std::size_t i = 0; i < a.duty_cycle.segments.size(); ++i) {
    EXPECT_EQ(a.duty_cycle.segments[i].start, b.duty_cycle.segments[i].start);
    EXPECT_EQ(a.duty_cycle.segments[i].speed_rpm, b.duty_cycle.segments[i].speed_rpm);
  }
  const auto &ta = a.thermal, &tb = b.thermal;
  EXPECT_EQ(ta.initial_temperature_c, tb.initial_temperature_c);
  EXPECT_EQ(ta.scheme, tb.scheme);
  EXPECT_EQ(ta.step, tb.step);
  EXPECT_EQ(ta.output_interval, tb.output_interval);
  EXPECT_EQ(ta.lumped_mass, tb.lumped_mass);
  ASSERT_EQ(ta.sources.size(), tb.sources.size());
  for (std::size_t i = 0; i < ta.sources.size(); ++i) {
    const auto &x = ta.sources[i], &y = tb.sources[i];
    EXPECT_EQ(x.name, y.name);
    EXPECT_EQ(x.body, y.body);
    EXPECT_EQ(x.law, y.law);
    EXPECT_EQ(x.power_ref, y.power_ref);
    EXPECT_EQ(x.ref_speed_rpm, y.ref_speed_rpm);
    EXPECT_EQ(x.exponent, y.exponent);
    EXPECT_EQ(x.palmgren_f0, y.palmgren_f0);
    EXPECT_EQ(x.palmgren_nu_cSt, y.palmgren_nu_cSt);
    expect_near_rel(x.palmgren_dm, y.palmgren_dm, tol, "palmgren_dm");
    EXPECT_EQ(x.palmgren_f1, y.palmgren_f1);
    EXPECT_EQ(x.palmgren_p1, y.palmgren_p1);
    EXPECT_EQ(x.temperature_coefficient, y.temperature_coefficient);
  }
  ASSERT_EQ(ta.convection.size(), tb.convection.size());
  for (std::size_t i = 0; i < ta.convection.size(); ++i) {
    const auto &x = ta.convection[i], &y = tb.convection[i];
    EXPECT_EQ(x.group, y.group);
    EXPECT_EQ(x.h, y.h);
    EXPECT_EQ(x.h_speed_gain, y.h_speed_gain);
    EXPECT_EQ(x.speed_ref_rpm, y.speed_ref_rpm);
    EXPECT_EQ(x.speed_exponent, y.speed_exponent);
    EXPECT_EQ(x.sink.time, y.sink.time);
    EXPECT_EQ(x.sink.value, y.sink.value);
  }
  ASSERT_EQ(ta.fluxes.size(), tb.fluxes.size());
  for (std::size_t i = 0; i < ta.fluxes.size(); ++i) {
    EXPECT_EQ(ta.fluxes[i].group, tb.fluxes[i].group);
    EXPECT_EQ(ta.fluxes[i].flux, tb.fluxes[i].flux);
    EXPECT_EQ(ta.fluxes[i].follows_speed, tb.fluxes[i].follows_speed);
    EXPECT_EQ(ta.fluxes[i].ref_speed_rpm, tb.fluxes[i].ref_speed_rpm);
  }
  EXPECT_EQ(a.mechanical.enabled, b.mechanical.enabled);
  EXPECT_EQ(a.mechanical.reference_temperature_c, b.mechanical.reference_temperature_c);
  EXPECT_EQ(a.mechanical.fixed_groups, b.mechanical.fixed_groups);
  ASSERT_EQ(a.mechanical.point_supports.size(), b.mechanical.point_supports.size());
  for (std::size_t i = 0; i < a.mechanical.point_supports.size(); ++i) {
    EXPECT_EQ(a.mechanical.point_supports[i].point, b.mechanical.point_supports[i].point);
    EXPECT_EQ(a.mechanical.point_supports[i].fixed, b.mechanical.point_supports[i].fixed);
  }
  EXPECT_EQ(a.mechanical.tcp_point, b.mechanical.tcp_point);
  EXPECT_EQ(a.mechanical.probe_points, b.mechanical.probe_points);
  EXPECT_EQ(a.outputs.plot_points, b.outputs.plot_points);
  EXPECT_EQ(a.outputs.fields, b.outputs.fields);
  EXPECT_EQ(a.outputs.fields_interval, b.outputs.fields_interval);
  EXPECT_EQ(a.placement.candidates, b.placement.candidates);
  EXPECT_EQ(a.placement.points, b.placement.points);
  EXPECT_EQ(a.placement.bodies, b.placement.bodies);
  EXPECT_EQ(a.placement.groups, b.placement.groups);
  EXPECT_EQ(a.placement.max_candidates, b.placement.max_candidates);
}

int index_of(const auto& items, const std::string& name) {
  for (std::size_t i = 0; i < items.size(); ++i)
    if (items[i].name == name) return static_cast<int>(i);
  ADD_FAILURE() << "no " << name;
  return -1;
}

const tt::core::NamedPoint& point(const CaseSpec& s, const std::string& id) {
  for (const auto& p : s.points)
    if (p.id == id) return p;
  throw std::runtime_error("no point " + id);
}

/// The resolved text without its first line (which names the source file).
std::string body_of(const std::string& resolved) {
  return resolved.substr(resolved.find('\n'));
}

}  // namespace

// ---------------------------------------------------------------------------------------------
// SB-1 as the spec describes it.

TEST(Sb1, HeaderMaterialsAndBodiesMatchTheSpec) {
  const CaseSpec s = read_case(sb1_file);
  EXPECT_EQ(s.source, sb1_file);
  EXPECT_EQ(s.name, "SB-1 P-1");
  EXPECT_EQ(s.machine, "SB-1");
  EXPECT_EQ(s.seed, 20260101u);

  ASSERT_EQ(s.materials.size(), 3u);
  EXPECT_EQ(s.materials[0].name, "grey_cast_iron");  // declaration order, not key order
  EXPECT_EQ(s.materials[2].name, "bearing");
  const auto& ci = s.materials[index_of(s.materials, "grey_cast_iron")];
  EXPECT_EQ(ci.density, 7250);
  EXPECT_EQ(ci.specific_heat, 510);
  EXPECT_EQ(ci.conductivity, 46);
  EXPECT_EQ(ci.youngs_modulus, 1.2e11);
  EXPECT_EQ(ci.poisson_ratio, 0.26);
  EXPECT_EQ(ci.expansion, 1.1e-5);
  const auto& st = s.materials[index_of(s.materials, "steel")];
  EXPECT_EQ(st.density, 7850);
  EXPECT_EQ(st.conductivity, 42);
  EXPECT_EQ(st.youngs_modulus, 2.1e11);
  EXPECT_EQ(st.poisson_ratio, 0.30);
  EXPECT_EQ(st.expansion, 1.2e-5);
  const auto& br = s.materials[index_of(s.materials, "bearing")];
  EXPECT_EQ(br.conductivity, 15);
  EXPECT_EQ(br.specific_heat, 460);

  ASSERT_EQ(s.bodies.size(), 4u);
  using K = tt::core::Primitive::Kind;
  const auto& housing = s.bodies[index_of(s.bodies, "housing")];
  EXPECT_EQ(s.materials[housing.material].name, "grey_cast_iron");
  ASSERT_EQ(housing.add.size(), 1u);
  EXPECT_EQ(housing.add[0].kind, K::box);
  EXPECT_EQ(housing.add[0].min, Eigen::Vector3d(-0.16, 0, 0));
  EXPECT_EQ(housing.add[0].max, Eigen::Vector3d(0.16, 0.30, 0.48));
  EXPECT_EQ(housing.add[0].where, "bodies[0].add[0]");
  ASSERT_EQ(housing.subtract.size(), 1u);
  EXPECT_EQ(housing.subtract[0].kind, K::cylinder);
  EXPECT_EQ(housing.subtract[0].axis, Eigen::Vector2d(0, 0.18));
  EXPECT_EQ(housing.subtract[0].radius, 0.060);
  EXPECT_EQ(housing.max_edge, 0.03);

  const auto& shaft = s.bodies[index_of(s.bodies, "shaft")];
  EXPECT_EQ(s.materials[shaft.material].name, "steel");
  EXPECT_EQ(shaft.add[0].kind, K::cylinder);
  EXPECT_EQ(shaft.add[0].radius, 0.045);
  EXPECT_EQ(shaft.add[0].z_min, -0.04);
  EXPECT_EQ(shaft.add[0].z_max, 0.58);

  const double centres[2] = {0.065, 0.425};
  int k = 0;
  for (const char* name : {"rear_bearing", "front_bearing"}) {
    const auto& b = s.bodies[index_of(s.bodies, name)];
    EXPECT_EQ(s.materials[b.material].name, "bearing");
    ASSERT_EQ(b.add.size(), 1u);
    EXPECT_EQ(b.add[0].kind, K::annulus);
    EXPECT_EQ(b.add[0].inner_radius, 0.045);
    EXPECT_EQ(b.add[0].radius, 0.060);
    EXPECT_NEAR(b.add[0].z_max - b.add[0].z_min, 0.05, 1e-15);
    EXPECT_NEAR(0.5 * (b.add[0].z_min + b.add[0].z_max), centres[k++], 1e-15);
  }
}

TEST(Sb1, BoundaryGroupsLoadsAndDutyCycleMatchTheSpec) {
  const CaseSpec s = read_case(sb1_file);
  ASSERT_EQ(s.groups.size(), 5u);
  const char* names[] = {"bed_contact", "air_gap", "bearing_seals", "shaft_outside",
                         "housing_outer"};
  const bool rest[] = {false, false, false, true, true};
  for (int i = 0; i < 5; ++i) {
    EXPECT_EQ(s.groups[i].name, names[i]);
    EXPECT_EQ(s.groups[i].rest, rest[i]) << names[i];
  }
  const auto& bed = s.groups[0].select.at(0);
  ASSERT_TRUE(bed.plane.has_value());
  EXPECT_EQ(*bed.plane, Eigen::Vector4d(0, 1, 0, 0));
  EXPECT_EQ(bed.side, tt::core::FaceSelector::Side::exterior);
  EXPECT_EQ(bed.bodies, std::vector<int>{index_of(s.bodies, "housing")});
  ASSERT_EQ(s.groups[1].select.size(), 2u);
  EXPECT_EQ(s.groups[1].select[1].on_cylinder->radius, 0.045);
  EXPECT_EQ(s.groups[1].select[1].within_max->z(), 0.48);

  // h per group as the spec lists them, all to 20 degC.
  const std::pair<const char*, double> h[] = {
      {"housing_outer", 8}, {"bed_contact", 60}, {"air_gap", 5}, {"shaft_outside", 15}};
  ASSERT_EQ(s.thermal.convection.size(), 4u);
  for (const auto& [group, value] : h) {
    bool found = false;
    for (const auto& c : s.thermal.convection) {
      if (s.groups[c.group].name != group) continue;
      found = true;
      EXPECT_EQ(c.h, value) << group;
      EXPECT_EQ(c.sink.value, std::vector<double>{20.0});
      EXPECT_EQ(c.sink.time, std::vector<double>{0.0});
    }
    EXPECT_TRUE(found) << group;
  }
  EXPECT_EQ(s.thermal.initial_temperature_c, 20);
  EXPECT_EQ(s.thermal.step, 12);
  EXPECT_EQ(s.thermal.output_interval, 72);
  EXPECT_EQ(s.thermal.scheme, tt::core::TimeScheme::backward_euler);

  // P-1 and the heat it delivers: 130 W x 6600 s = 858 kJ.
  const auto& dc = s.duty_cycle;
  ASSERT_EQ(dc.segments.size(), 5u);
  const double starts[] = {0, 600, 900, 2100, 2400};
  const double rpm[] = {3000, 0, 3000, 0, 3000};
  for (int i = 0; i < 5; ++i) {
    EXPECT_EQ(dc.segments[i].start, starts[i]);
    EXPECT_EQ(dc.segments[i].speed_rpm, rpm[i]);
  }
  EXPECT_EQ(dc.end, 7200);
  ASSERT_EQ(s.thermal.sources.size(), 2u);
  double energy = 0;
  for (std::size_t i = 0; i < dc.segments.size(); ++i) {
    const double t1 = i + 1 < dc.segments.size() ? dc.segments[i + 1].start : dc.end;
    for (const auto& src : s.thermal.sources)
      energy += src.power_ref *
                std::pow(dc.segments[i].speed_rpm / src.ref_speed_rpm, src.exponent) *
                (t1 - dc.segments[i].start);
  }
  EXPECT_NEAR(energy, 858e3, 1e-6);
  const auto& front = s.thermal.sources[index_of(s.thermal.sources, "front_bearing_friction")];
  EXPECT_EQ(s.bodies[front.body].name, "front_bearing");
  EXPECT_EQ(front.power_ref, 80);

  EXPECT_TRUE(s.mechanical.enabled);
  EXPECT_EQ(s.mechanical.fixed_groups, std::vector<int>{0});
  EXPECT_EQ(s.mechanical.tcp_point, "TCP");
  EXPECT_EQ(s.mechanical.probe_points, (std::vector<std::string>{"Z1", "Z2"}));
  EXPECT_EQ(s.outputs.plot_points, (std::vector<std::string>{"T02", "T10", "T18"}));
  EXPECT_TRUE(s.outputs.fields);
}

TEST(Sb1, PointsAreC54InSpecOrderPlusTcpAndProbes) {
  const CaseSpec s = read_case(sb1_file);
  ASSERT_EQ(s.points.size(), 57u);
  EXPECT_EQ(point(s, "T07").position, Eigen::Vector3d(-0.08, 0.30, 0.20));
  EXPECT_EQ(point(s, "T19").position, Eigen::Vector3d(-0.16, 0.08, 0.04));
  EXPECT_EQ(point(s, "TCP").position, Eigen::Vector3d(0, 0.18, 0.58));
  EXPECT_EQ(point(s, "Z1").position, Eigen::Vector3d(0, 0.18, 0.50));
  EXPECT_EQ(point(s, "Z2").position, Eigen::Vector3d(0, 0.18, 0.57));
  EXPECT_EQ(point(s, "TCP").on_group, -1);
  // C-54: face by face (top, left, right), then z ascending, then the transverse coordinate.
  const double zs[] = {0.04, 0.12, 0.20, 0.28, 0.36, 0.44};
  const double xs[] = {-0.08, 0.0, 0.08}, ys[] = {0.08, 0.16, 0.24};
  const int outer = index_of(s.groups, "housing_outer");
  int id = 1;
  for (int face = 0; face < 3; ++face) {
    for (double z : zs) {
      for (int j = 0; j < 3; ++j) {
        const Eigen::Vector3d expected = face == 0   ? Eigen::Vector3d(xs[j], 0.30, z)
                                         : face == 1 ? Eigen::Vector3d(-0.16, ys[j], z)
                                                     : Eigen::Vector3d(0.16, ys[j], z);
        const auto& p = s.points[id - 1];
        EXPECT_EQ(p.id, (id < 10 ? "T0" : "T") + std::to_string(id));
        EXPECT_EQ(p.position, expected) << p.id;
        EXPECT_EQ(p.on_group, outer) << p.id;
        ++id;
      }
    }
  }
}

TEST(Sb1, MillimetreCaseGivesTheSameSiSpec) {
  const CaseSpec m = read_case(sb1_file);
  const CaseSpec mm = read_case(sb1_mm_file);
  expect_same(mm, m, 1e-15);
  // Dividing an exact mm decimal by 1000 rounds to the same double as the m decimal.
  EXPECT_EQ(body_of(resolved_case_toml(mm)), body_of(resolved_case_toml(m)));
}

TEST_F(CaseFiles, Sb1ResolvedTomlReadsBackToTheSameSpec) {
  const CaseSpec s = read_case(sb1_file);
  const std::string text = resolved_case_toml(s);
  EXPECT_NE(text.find("length_unit = \"m\""), std::string::npos);
  EXPECT_NE(text.find("lumped_mass = false"), std::string::npos);  // defaults explicit
  EXPECT_NE(text.find("fields = true"), std::string::npos);
  const CaseSpec back = read_case(write("case.resolved.toml", text));
  EXPECT_EQ(back.source, dir_ / "case.resolved.toml");
  expect_same(back, s);
  EXPECT_EQ(body_of(resolved_case_toml(back)), body_of(text));
}

// ---------------------------------------------------------------------------------------------
// A small case that uses every feature the format has.

const char* const mini_case = R"(# a block with a pin in it
[case]
name = "mini"

[geometry]
length_unit = "m"

[materials.steel]
density_kg_m3 = 7850.0
specific_heat_J_kgK = 460.0
conductivity_W_mK = 42.0
youngs_modulus_Pa = 2.1e11
poisson_ratio = 0.3
expansion_per_K = 1.2e-5

[[bodies]]
name = "block"
material = "steel"
max_edge = 0.01
add = [ { box = { min = [0.0, 0.0, 0.0], max = [0.1, 0.1, 0.1] } } ]

[[bodies]]
name = "pin"
material = "steel"
max_edge = 0.005
add = [ { cylinder = { axis = [0.05, 0.05], radius = 0.01, z = [0.1, 0.2] } } ]

[[boundary]]
name = "base"
select = [ { bodies = ["block"], plane = { normal = [0.0, 0.0, 1.0], offset = 0.0 } } ]

[[boundary]]
name = "rest"
rest = true
select = [ {} ]

[thermal]
step_s = 10.0

[[thermal.convection]]
group = "rest"
h_W_m2K = 10.0
sink_degC = 20.0

[[thermal.heat_sources]]
name = "pin_heat"
body = "pin"
power_ref_W = 10.0
ref_speed_rpm = 1000.0

[duty_cycle]
end_s = 100.0
segments = [ { start_s = 0.0, speed_rpm = 1000.0 }, { start_s = 50.0, speed_rpm = 0.0 } ]

[mechanical]
fixed = ["base"]
tcp = "P1"
probes = ["P1", "P2"]

[outputs]
plot_points = ["P1"]

[points]
list = [ { id = "P1", position = [0.05, 0.05, 0.2] }, { id = "P2", position = [0.05, 0.05, 0.15], on = "rest" } ]
)";

std::string replaced(std::string text, const std::string& from, const std::string& to) {
  const auto at = text.find(from);
  if (at == std::string::npos) throw std::runtime_error("fixture has no '" + from + "'");
  return text.replace(at, from.size(), to);
}

TEST_F(CaseFiles, MiniCaseParsesWithDefaultsFilled) {
  const CaseSpec s = read_case(write("mini.toml", mini_case));
  EXPECT_EQ(s.machine, "");
  EXPECT_EQ(s.seed, 1u);
  EXPECT_EQ(s.mesh.order, 2);
  EXPECT_EQ(s.mesh.circle_segments, 48);
  EXPECT_EQ(s.thermal.output_interval, 72);
  EXPECT_EQ(s.thermal.initial_temperature_c, 20);
  EXPECT_EQ(s.thermal.sources.at(0).law, tt::core::HeatSource::Law::speed_power);
  EXPECT_EQ(s.thermal.sources.at(0).exponent, 1.0);
  EXPECT_EQ(s.thermal.convection.at(0).speed_ref_rpm, 1.0);
  EXPECT_EQ(s.groups.at(1).select.at(0).bodies, std::vector<int>{});
  EXPECT_EQ(s.points.at(1).on_group, 1);
  EXPECT_TRUE(s.mechanical.enabled);
  EXPECT_EQ(s.mechanical.reference_temperature_c, 20);
}

TEST_F(CaseFiles, EveryFeatureInMillimetresRoundTrips) {
  write("part.stl", "solid part\nendsolid part\n");
  // A spreadsheet's quoted field is read as its content.
  write("p1.csv", "time_s,speed_rpm\n0,1500\n\"30\", 0\n# pause\n60,3000\n");
  std::string text = replaced(mini_case, "length_unit = \"m\"", "length_unit = \"mm\"");
  text = replaced(text, "max = [0.1, 0.1, 0.1] } } ]",
                  "max = [100, 100, 100] } }, { surface = { file = \"part.stl\" } } ]\n"
                  "subtract = [ { annulus = { axis = [50, 50], inner_radius = 5.0, "
                  "outer_radius = 8.0, z = [90.0, 100.0] } } ]");
  text = replaced(text, "max_edge = 0.01", "max_edge = 10");
  text = replaced(text, "max_edge = 0.005", "max_edge = 5");
  text = replaced(text, "axis = [0.05, 0.05], radius = 0.01, z = [0.1, 0.2]",
                  "axis = [50, 50], radius = 10, z = [100, 200]");
  text = replaced(text, "normal = [0.0, 0.0, 1.0], offset = 0.0",
                  "normal = [0.0, 0.0, -2.0], offset = 0.0");
  text = replaced(text, "select = [ {} ]",
                  "select = [ { side = \"any\" } ]\n\n[[boundary]]\nname = \"joint\"\n"
                  "select = [ { bodies = [\"pin\"], side = \"interface\", other_bodies = "
                  "[\"block\"], on_cylinder = { axis = [50, 50], radius = 10 }, within = "
                  "{ min = [0, 0, 90], max = [100, 100, 100] } } ]");
  text = replaced(text, "step_s = 10.0",
                  "step_s = 5.0\noutput_interval_s = 15.0\nscheme = \"crank_nicolson\"\n"
                  "lumped_mass = true\ninitial_temperature_degC = 21.5");
  text = replaced(text, "sink_degC = 20.0",
                  "h_speed_gain_W_m2K = 4.0\nspeed_ref_rpm = 3000.0\nspeed_exponent = 0.8\n"
                  "sink_table = [[0.0, 20.0], [40.0, 23.5]]");
  text = replaced(text, "ref_speed_rpm = 1000.0",
                  "ref_speed_rpm = 1000.0\nexponent = 1.3\ntemperature_coefficient_per_K = "
                  "-0.002\n\n[[thermal.heat_sources]]\nname = \"steady\"\nbody = \"block\"\n"
                  "law = \"constant\"\npower_ref_W = 3.0\n\n[[thermal.heat_sources]]\nname = "
                  "\"palm\"\nbody = \"pin\"\nlaw = \"palmgren\"\npalmgren_f0 = 1.5\n"
                  "palmgren_nu_cSt = 20.0\npalmgren_dm = 70.0\npalmgren_f1 = 0.0004\n"
                  "palmgren_p1_N = 500.0\n\n[[thermal.surface_flux]]\ngroup = \"base\"\n"
                  "flux_W_m2 = -50.0\nfollows_speed = true\nref_speed_rpm = 2000.0");
  text = replaced(text,
                  "segments = [ { start_s = 0.0, speed_rpm = 1000.0 }, { start_s = 50.0, "
                  "speed_rpm = 0.0 } ]",
                  "csv = \"p1.csv\"");
  text = replaced(text, "[mechanical]",
                  "[mechanical]\nreference_temperature_degC = 19.0\npoint_supports = [ { point "
                  "= \"P2\", fixed = [\"z\", \"x\"] }, { point = \"P1\" } ]");
  text = replaced(text, "plot_points = [\"P1\"]",
                  "plot_points = [\"P1\"]\nfields = false\nfields_interval_s = 30.0");
  text = replaced(text, "position = [0.05, 0.05, 0.2]", "position = [50, 50, 200]");
  text = replaced(text, "position = [0.05, 0.05, 0.15]", "position = [50, 50, 150]");
  text = replaced(text, "[case]\nname = \"mini\"",
                  "[case]\nname = \"mini\"\nseed = 7\n"
                  "machine = \"bench \\\"A\\\"\"");
  text +=
      "\n[mesh]\norder = 1\ncircle_segments = 24\nradius_edge_ratio = 2.0\n"
      "min_dihedral_deg = 15.0\nmax_tets = 2e6\ntime_limit_s = 600.0\nmemory_limit_GB = 4.5\n";
  text +=
      "\n[placement]\ncandidates = \"surface\"\nbodies = [\"pin\"]\ngroups = [\"joint\", "
      "\"base\"]\n"
      "max_candidates = 500\n";

  const CaseSpec s = read_case(write("full.toml", text));
  // Spot checks that the features landed in SI.
  EXPECT_EQ(s.machine, "bench \"A\"");
  EXPECT_EQ(s.bodies[0].add.at(1).kind, tt::core::Primitive::Kind::surface_file);
  EXPECT_EQ(s.bodies[0].add.at(1).file, dir_ / "part.stl");
  EXPECT_EQ(s.bodies[0].add.at(1).file_scale, 1e-3);
  EXPECT_EQ(s.bodies[0].subtract.at(0).inner_radius, 0.005);
  EXPECT_EQ(*s.groups[0].select[0].plane, Eigen::Vector4d(0, 0, -1, 0));
  EXPECT_EQ(s.groups[2].select[0].other_bodies, std::vector<int>{0});
  EXPECT_EQ(s.groups[2].select[0].within_min->z(), 0.09);
  EXPECT_EQ(s.thermal.scheme, tt::core::TimeScheme::crank_nicolson);
  EXPECT_EQ(s.thermal.convection[0].sink.value, (std::vector<double>{20.0, 23.5}));
  EXPECT_EQ(s.thermal.sources.at(2).palmgren_dm, 0.07);
  EXPECT_EQ(s.thermal.sources.at(2).palmgren_p1, 500);
  EXPECT_EQ(s.thermal.fluxes.at(0).flux, -50);
  ASSERT_EQ(s.duty_cycle.segments.size(), 3u);
  EXPECT_EQ(s.duty_cycle.segments[1].start, 30);
  EXPECT_EQ(s.duty_cycle.segments[2].speed_rpm, 3000);
  EXPECT_EQ(s.points[0].position, Eigen::Vector3d(0.05, 0.05, 0.2));
  EXPECT_EQ(s.mesh.order, 1);
  EXPECT_EQ(s.mesh.max_tets, 2e6);
  EXPECT_EQ(s.mesh.time_limit_s, 600);
  EXPECT_EQ(s.mesh.memory_limit_GB, 4.5);
  EXPECT_FALSE(s.outputs.fields);
  EXPECT_EQ(s.outputs.fields_interval, 30);
  ASSERT_EQ(s.mechanical.point_supports.size(), 2u);
  EXPECT_EQ(s.mechanical.point_supports[0].point, "P2");
  EXPECT_EQ(s.mechanical.point_supports[0].fixed, (std::array<bool, 3>{true, false, true}));
  EXPECT_EQ(s.mechanical.point_supports[1].fixed, (std::array<bool, 3>{true, true, true}));
  EXPECT_EQ(s.placement.candidates, tt::core::PlacementSpec::Candidates::surface);
  EXPECT_EQ(s.placement.bodies, std::vector<int>{1});
  EXPECT_EQ(s.placement.groups, (std::vector<int>{2, 0}));
  EXPECT_EQ(s.placement.max_candidates, 500);

  const std::string resolved = resolved_case_toml(s);
  fs::create_directories(dir_ / "elsewhere");  // the resolved file lives beside the results
  const CaseSpec back = read_case(write("elsewhere/case.resolved.toml", resolved));
  expect_same(back, s);
  EXPECT_EQ(body_of(resolved_case_toml(back)), body_of(resolved));
}

// ---------------------------------------------------------------------------------------------
// Bad input: each mutation of the mini case must fail with the file, the line, the key path
// and what was expected.

struct BadInput {
  const char* name;
  std::string from, to;   /// mutation of mini_case
  std::string line_text;  /// a text on the line the message must point to ("" for none)
  std::string key;        /// key path the message must name
  std::string expected;   /// fragment saying what was expected or suggested
};

std::ostream& operator<<(std::ostream& os, const BadInput& b) {
  return os << b.name;
}

class BadCase : public CaseFiles, public ::testing::WithParamInterface<BadInput> {};

TEST_P(BadCase, IsReportedWithFileLineAndKey) {
  const BadInput& b = GetParam();
  write("part.csv", "time_s,speed_rpm\n0,100\n");
  const std::string text = replaced(mini_case, b.from, b.to);
  const fs::path file = write("bad.toml", text);
  std::string message;
  try {
    read_case(file);
    FAIL() << "no error for " << b.name;
  } catch (const CaseError& e) {
    message = e.what();
  }
  SCOPED_TRACE(message);
  RecordProperty("message", message);  // --gtest_output=xml shows every message for review
  if (!b.line_text.empty()) {
    const auto at = text.find(b.line_text);
    ASSERT_NE(at, std::string::npos);
    const int line = 1 + static_cast<int>(std::count(text.begin(), text.begin() + at, '\n'));
    EXPECT_EQ(message.rfind(file.string() + ":" + std::to_string(line) + ": ", 0), 0u);
  } else {
    EXPECT_EQ(message.rfind(file.string() + ": ", 0), 0u);
  }
  EXPECT_NE(message.find(b.key), std::string::npos);
  EXPECT_NE(message.find(b.expected), std::string::npos);
}

const BadInput bad_inputs[] = {
    {"toml_syntax", "max_edge = 0.01", "max_edge = 0.01 0.02", "max_edge = 0.01 0.02", "",
     "not valid TOML"},
    {"unknown_key", "conductivity_W_mK", "conductivity_W_Mk", "conductivity_W_Mk",
     "materials.steel.conductivity_W_Mk = 42.0", "did you mean 'conductivity_W_mK'?"},
    {"unknown_key_without_unit", "density_kg_m3", "density", "density =", "materials.steel.density",
     "did you mean 'density_kg_m3'?"},
    {"unknown_table", "[outputs]", "[output]", "[output]", "output", "did you mean 'outputs'?"},
    {"unknown_inline_key", "radius = 0.01", "radius_m = 0.01", "radius_m",
     "bodies[1].add[0].cylinder.radius_m", "did you mean 'radius'?"},
    {"unknown_primitive", "{ cylinder = {", "{ cilinder = {", "cilinder",
     "bodies[1].add[0].cilinder", "did you mean 'cylinder'?"},
    {"two_primitives_in_one", "{ box = { min = [0.0, 0.0, 0.0], max = [0.1, 0.1, 0.1] } }",
     "{ box = { min = [0.0, 0.0, 0.0], max = [0.1, 0.1, 0.1] }, cylinder = {} }", "cylinder = {}",
     "bodies[0].add[0]", "exactly one of"},
    {"missing_key", "density_kg_m3 = 7850.0\n", "", "[materials.steel]",
     "materials.steel.density_kg_m3", "missing"},
    {"missing_name", "name = \"mini\"\n", "", "[case]", "case.name", "missing"},
    {"wrong_type", "conductivity_W_mK = 42.0", "conductivity_W_mK = \"42\"", "conductivity_W_mK",
     "materials.steel.conductivity_W_mK = \"42\"", "expected a number, got a string"},
    {"wrong_type_integer", "tcp = \"P1\"", "tcp = \"P1\"\nenabled = 1", "enabled = 1",
     "mechanical.enabled = 1", "expected true or false"},
    {"points_not_a_table", "[points]", "[[points]]", "[[points]]",
     "points = ", "expected a table, got an array"},
    {"convection_not_an_array", "[[thermal.convection]]", "[thermal.convection]",
     "[thermal.convection]", "thermal.convection = ", "expected an array of tables"},
    {"nan", "conductivity_W_mK = 42.0", "conductivity_W_mK = nan", "conductivity_W_mK",
     "materials.steel.conductivity_W_mK = nan", "finite"},
    {"inf", "h_W_m2K = 10.0", "h_W_m2K = inf", "h_W_m2K", "thermal.convection[0].h_W_m2K = inf",
     "finite"},
    {"negative_conductivity", "conductivity_W_mK = 42.0", "conductivity_W_mK = -45",
     "conductivity_W_mK", "materials.steel.conductivity_W_mK = -45", "must be > 0"},
    {"zero_density", "density_kg_m3 = 7850.0", "density_kg_m3 = 0.0", "density_kg_m3",
     "materials.steel.density_kg_m3 = 0.0", "must be > 0"},
    {"zero_specific_heat", "specific_heat_J_kgK = 460.0", "specific_heat_J_kgK = 0",
     "specific_heat_J_kgK", "materials.steel.specific_heat_J_kgK", "must be > 0"},
    {"negative_youngs_modulus", "youngs_modulus_Pa = 2.1e11", "youngs_modulus_Pa = -2.1e11",
     "youngs_modulus_Pa", "materials.steel.youngs_modulus_Pa", "must be > 0"},
    {"poisson_half", "poisson_ratio = 0.3", "poisson_ratio = 0.5", "poisson_ratio",
     "materials.steel.poisson_ratio = 0.5", "(-1, 0.5)"},
    {"poisson_minus_one", "poisson_ratio = 0.3", "poisson_ratio = -1.0", "poisson_ratio",
     "materials.steel.poisson_ratio = -1.0", "(-1, 0.5)"},
    {"negative_radius", "radius = 0.01", "radius = -0.01", "radius = -0.01",
     "bodies[1].add[0].cylinder.radius = -0.01", "must be > 0"},
    {"zero_max_edge", "max_edge = 0.005", "max_edge = 0", "max_edge = 0\n",
     "bodies[1].max_edge = 0", "must be > 0"},
    {"box_min_not_below_max", "max = [0.1, 0.1, 0.1]", "max = [0.1, -0.1, 0.1]", "max = [0.1, -0.1",
     "bodies[0].add[0].box.max", "must exceed min"},
    {"z0_not_below_z1", "z = [0.1, 0.2]", "z = [0.2, 0.1]", "z = [0.2, 0.1]",
     "bodies[1].add[0].cylinder.z", "z0 < z1"},
    {"annulus_inner_not_below_outer",
     "{ cylinder = { axis = [0.05, 0.05], radius = 0.01, z = [0.1, 0.2] } }",
     "{ annulus = { axis = [0.05, 0.05], inner_radius = 0.02, outer_radius = 0.01, z = [0.1, "
     "0.2] } }",
     "annulus", "bodies[1].add[0].annulus.outer_radius = 0.01", "must exceed inner_radius"},
    {"axis_wrong_length", "axis = [0.05, 0.05]", "axis = [0.05, 0.05, 0.0]",
     "axis = [0.05, 0.05, 0", "bodies[1].add[0].cylinder.axis", "expected 2 numbers"},
    {"surface_file_missing", "{ box = { min = [0.0, 0.0, 0.0], max = [0.1, 0.1, 0.1] } }",
     "{ surface = { file = \"nope.stl\" } }", "nope.stl", "bodies[0].add[0].surface.file",
     "no such file"},
    {"unknown_length_unit", "length_unit = \"m\"", "length_unit = \"cm\"", "length_unit",
     "geometry.length_unit = \"cm\"", "unknown value"},
    {"negative_h", "h_W_m2K = 10.0", "h_W_m2K = -1.0", "h_W_m2K",
     "thermal.convection[0].h_W_m2K = -1.0", "must be >= 0"},
    {"two_convections_on_one_group", "sink_degC = 20.0",
     "sink_degC = 20.0\n[[thermal.convection]]\ngroup = \"rest\" # dup\nh_W_m2K = 1.0\n"
     "sink_degC = 20.0",
     "# dup", "thermal.convection[1].group = \"rest\"", "already has a convection entry"},
    {"sink_missing", "sink_degC = 20.0\n", "", "[[thermal.convection]]",
     "thermal.convection[0].sink_degC", "missing"},
    {"sink_table_descending", "sink_degC = 20.0", "sink_table = [[0.0, 20.0], [0.0, 21.0]]",
     "sink_table", "thermal.convection[0].sink_table[1]", "time must exceed"},
    {"zero_step", "step_s = 10.0", "step_s = 0.0", "step_s", "thermal.step_s = 0.0", "must be > 0"},
    {"step_longer_than_run", "step_s = 10.0", "step_s = 500.0", "step_s", "thermal.step_s = 500.0",
     "must not exceed the run"},
    {"negative_output_interval", "step_s = 10.0", "step_s = 10.0\noutput_interval_s = -72",
     "output_interval_s", "thermal.output_interval_s = -72", "must be > 0"},
    {"unknown_scheme", "step_s = 10.0", "step_s = 10.0\nscheme = \"crank_nicholson\"", "scheme",
     "thermal.scheme = \"crank_nicholson\"", "did you mean 'crank_nicolson'?"},
    {"unknown_law", "power_ref_W = 10.0", "power_ref_W = 10.0\nlaw = \"speed\"",
     "law =", "thermal.heat_sources[0].law = \"speed\"", "did you mean 'speed_power'?"},
    {"key_of_another_law", "power_ref_W = 10.0", "power_ref_W = 10.0\npalmgren_f0 = 1.5",
     "palmgren_f0", "thermal.heat_sources[0].palmgren_f0", "not used by law = \"speed_power\""},
    {"unknown_side", "select = [ {} ]", "select = [ { side = \"exteriour\" } ]", "exteriour",
     "boundary[1].select[0].side = \"exteriour\"", "did you mean 'exterior'?"},
    {"other_bodies_without_interface", "select = [ {} ]",
     "select = [ { other_bodies = [\"pin\"] } ]", "other_bodies",
     "boundary[1].select[0].other_bodies", "side = \"interface\""},
    {"zero_plane_normal", "normal = [0.0, 0.0, 1.0]", "normal = [0.0, 0.0, 0.0]",
     "normal =", "boundary[0].select[0].plane.normal", "must not be zero"},
    {"within_min_not_below_max", "select = [ {} ]",
     "select = [ { within = { min = [0, 0, 1], max = [1, 1, 1] } } ]", "within",
     "boundary[1].select[0].within.max", "(z is not)"},
    {"unknown_material", "material = \"steel\"", "material = \"steal\"", "steal",
     "bodies[0].material = \"steal\"", "did you mean 'steel'?"},
    {"heat_source_on_missing_body", "body = \"pin\"", "body = \"pinn\"", "pinn",
     "thermal.heat_sources[0].body = \"pinn\"", "did you mean 'pin'?"},
    {"unknown_body_in_selector", "bodies = [\"block\"]", "bodies = [\"blocks\"]", "blocks",
     "boundary[0].select[0].bodies[0] = \"blocks\"", "did you mean 'block'?"},
    {"unknown_convection_group", "group = \"rest\"", "group = \"rst\"", "rst",
     "thermal.convection[0].group = \"rst\"", "did you mean 'rest'?"},
    {"unknown_fixed_group", "fixed = [\"base\"]", "fixed = [\"bas\"]", "[\"bas\"]",
     "mechanical.fixed[0] = \"bas\"", "did you mean 'base'?"},
    {"unknown_point_group", "on = \"rest\"", "on = \"top\"", "on = \"top\"",
     "points.list[1].on = \"top\"", "no boundary group"},
    {"tcp_not_a_point", "tcp = \"P1\"", "tcp = \"P9\"", "P9", "mechanical.tcp = \"P9\"",
     "no point of that name"},
    {"probe_not_a_point", "probes = [\"P1\", \"P2\"]", "probes = [\"P1\", \"Q2\"]", "Q2",
     "mechanical.probes[1] = \"Q2\"", "did you mean 'P2'?"},
    {"one_probe", "probes = [\"P1\", \"P2\"]", "probes = [\"P1\"]", "probes", "mechanical.probes",
     "two point ids"},
    {"plot_point_not_a_point", "plot_points = [\"P1\"]", "plot_points = [\"p1\"]", "plot_points",
     "outputs.plot_points[0] = \"p1\"", "did you mean 'P1'?"},
    {"duplicate_body", "name = \"pin\"", "name = \"block\" # dup", "# dup",
     "bodies[1].name = \"block\"", "a second body"},
    {"duplicate_group", "name = \"rest\"", "name = \"base\" # dup", "# dup",
     "boundary[1].name = \"base\"", "a second boundary group"},
    {"duplicate_point", "{ id = \"P2\"", "{ id = \"P1\"", "list = [", "points.list[1].id = \"P1\"",
     "a second point"},
    {"duplicate_heat_source", "ref_speed_rpm = 1000.0",
     "ref_speed_rpm = 1000.0\n[[thermal.heat_sources]]\nname = \"pin_heat\" # dup\nbody = "
     "\"pin\"\nlaw = \"constant\"\npower_ref_W = 1.0",
     "# dup", "thermal.heat_sources[1].name = \"pin_heat\"", "a second heat source"},
    {"segments_not_ascending", "start_s = 50.0", "start_s = 0.0", "segments",
     "duty_cycle.segments[1].start_s = 0.0", "must exceed the previous start"},
    {"segments_not_from_zero", "start_s = 0.0", "start_s = 5.0", "segments",
     "duty_cycle.segments[0].start_s = 5.0", "must start at 0"},
    {"end_before_last_start", "end_s = 100.0", "end_s = 50.0", "end_s", "duty_cycle.end_s = 50.0",
     "must exceed the last segment's start"},
    {"negative_speed", "speed_rpm = 0.0", "speed_rpm = -3000.0", "segments",
     "duty_cycle.segments[1].speed_rpm = -3000.0", "must be >= 0"},
    {"segments_and_csv", "end_s = 100.0", "end_s = 100.0\ncsv = \"part.csv\"",
     "csv =", "duty_cycle.csv", "not both"},
    {"order_three", "[outputs]", "[mesh]\norder = 3\n\n[outputs]", "order", "mesh.order = 3",
     "must be 1 or 2"},
    {"order_not_integer", "[outputs]", "[mesh]\norder = 2.0\n\n[outputs]", "order",
     "mesh.order = 2.0", "expected an integer"},
    {"support_on_unknown_point", "tcp = \"P1\"",
     "tcp = \"P1\"\npoint_supports = [ { point = \"P3\" } ]", "point_supports",
     "mechanical.point_supports[0].point = \"P3\"", "no point of that name"},
    {"support_in_unknown_direction", "tcp = \"P1\"",
     "tcp = \"P1\"\npoint_supports = [ { point = \"P2\", fixed = [\"x\", \"w\"] } ]",
     "point_supports", "mechanical.point_supports[0].fixed[1] = \"w\"", "unknown value"},
    {"zero_fields_interval", "plot_points = [\"P1\"]",
     "plot_points = [\"P1\"]\nfields_interval_s = 0", "fields_interval_s",
     "outputs.fields_interval_s = 0", "must be > 0"},
    {"fixed_missing", "fixed = [\"base\"]\n", "", "[mechanical]", "mechanical.fixed", "missing"},
    {"placement_unknown_key", "[points]",
     "[placement]\ncandidates = \"surface\"\nbodies = [\"block\"]\nmax_candidate = 5\n\n[points]",
     "max_candidate =", "placement.max_candidate = 5", "did you mean 'max_candidates'?"},
    {"placement_unknown_kind", "[points]", "[placement]\ncandidates = \"surfaces\"\n\n[points]",
     "surfaces", "placement.candidates = \"surfaces\"", "did you mean 'surface'?"},
    {"placement_unknown_body", "[points]",
     "[placement]\ncandidates = \"surface\"\nbodies = [\"blok\"]\n\n[points]", "blok",
     "placement.bodies[0] = \"blok\"", "did you mean 'block'?"},
    {"placement_unknown_group", "[points]",
     "[placement]\ncandidates = \"surface\"\ngroups = [\"rest\", \"bse\"]\n\n[points]", "bse",
     "placement.groups[1] = \"bse\"", "did you mean 'base'?"},
    {"placement_surface_of_nothing", "[points]",
     "[placement]\ncandidates = \"surface\"\n\n[points]",
     "candidates =", "placement.candidates = \"surface\"", "needs bodies = [body names] or groups"},
    {"placement_bodies_with_points", "[points]", "[placement]\nbodies = [\"block\"]\n\n[points]",
     "bodies = [\"block\"]\n\n", "placement.bodies", "only used with candidates = \"surface\""},
    {"placement_tcp_as_sensor", "[points]", "[placement]\npoints = [\"P1\"] # tcp\n\n[points]",
     "# tcp", "placement.points[0] = \"P1\"", "is the TCP"},
    {"placement_negative_max", "[points]",
     "[placement]\ncandidates = \"surface\"\ngroups = [\"rest\"]\nmax_candidates = -3\n\n[points]",
     "max_candidates", "placement.max_candidates = -3", "must lie in"},
    // Issue 14: bounds named with their real limits, temperatures above absolute zero, counts
    // that input decides bounded before anything of that size exists.
    {"circle_segments_beyond_limit", "[outputs]", "[mesh]\ncircle_segments = 100001\n\n[outputs]",
     "circle_segments", "mesh.circle_segments = 100001", "must lie in [8, 100000]"},
    {"circle_segments_below_limit", "[outputs]", "[mesh]\ncircle_segments = 7\n\n[outputs]",
     "circle_segments", "mesh.circle_segments = 7", "must lie in [8, 100000]"},
    {"min_dihedral_beyond_tetgen", "[outputs]", "[mesh]\nmin_dihedral_deg = 30.0\n\n[outputs]",
     "min_dihedral_deg", "mesh.min_dihedral_deg = 30.0", "must lie in [0, 18]"},
    {"radius_edge_ratio_near_one", "[outputs]", "[mesh]\nradius_edge_ratio = 1.001\n\n[outputs]",
     "radius_edge_ratio", "mesh.radius_edge_ratio = 1.001", "must be >= 1.1"},
    {"zero_max_tets", "[outputs]", "[mesh]\nmax_tets = 0\n\n[outputs]", "max_tets",
     "mesh.max_tets = 0", "must be > 0"},
    {"nan_time_limit", "[outputs]", "[mesh]\ntime_limit_s = nan\n\n[outputs]", "time_limit_s",
     "mesh.time_limit_s = nan", "finite"},
    {"negative_memory_limit", "[outputs]", "[mesh]\nmemory_limit_GB = -1.0\n\n[outputs]",
     "memory_limit_GB", "mesh.memory_limit_GB = -1.0", "must be > 0"},
    {"initial_temperature_below_absolute_zero", "step_s = 10.0",
     "step_s = 10.0\ninitial_temperature_degC = -300.0", "initial_temperature_degC",
     "thermal.initial_temperature_degC = -300.0", "absolute zero"},
    {"sink_below_absolute_zero", "sink_degC = 20.0", "sink_degC = -273.2", "sink_degC",
     "thermal.convection[0].sink_degC = -273.2", "absolute zero"},
    {"sink_table_below_absolute_zero", "sink_degC = 20.0",
     "sink_table = [[0.0, 20.0], [50.0, -300.0]]", "sink_table",
     "thermal.convection[0].sink_table[1][1] = -300.0", "absolute zero"},
    {"reference_temperature_below_absolute_zero", "tcp = \"P1\"",
     "tcp = \"P1\"\nreference_temperature_degC = -500", "reference_temperature_degC",
     "mechanical.reference_temperature_degC = -500", "absolute zero"},
    {"too_many_time_steps", "step_s = 10.0", "step_s = 1e-7", "step_s", "thermal.step_s = 1e-07",
     "more than the limit of 5000000"},
    {"run_too_long_for_its_step", "end_s = 100.0", "end_s = 1e12", "step_s = 10.0",
     "thermal.step_s = 10.0", "1e+11 time steps"},
    {"too_many_output_times", "step_s = 10.0", "step_s = 10.0\noutput_interval_s = 1e-300",
     "output_interval_s", "thermal.output_interval_s = 1e-300", "more than the limit of 200000"},
};

INSTANTIATE_TEST_SUITE_P(CaseReader, BadCase, ::testing::ValuesIn(bad_inputs),
                         [](const auto& info) { return std::string(info.param.name); });

// ---------------------------------------------------------------------------------------------
// Errors in the duty-cycle CSV point into the CSV.

TEST_F(CaseFiles, DutyCycleCsvErrorsNameTheCsvLine) {
  const std::string text = replaced(
      mini_case,
      "segments = [ { start_s = 0.0, speed_rpm = 1000.0 }, { start_s = 50.0, speed_rpm = 0.0 } ]",
      "csv = \"p1.csv\"");
  const fs::path file = write("case.toml", text);
  const std::pair<std::string, std::string> bad[] = {
      {"time,speed\n0,1\n", "p1.csv:1: header"},
      {"time_s,speed_rpm\n0,1000\n20,fast\n", "p1.csv:3: speed_rpm = \"fast\""},
      {"time_s,speed_rpm\n0,1000\n20,0\n20,5\n", "p1.csv:4: time_s = 20.0: must exceed"},
      {"time_s,speed_rpm\n5,1000\n", "p1.csv:2: time_s = 5.0: the first row must start at 0"},
      {"time_s,speed_rpm\n0,1000\n200,0\n", "duty_cycle.end_s = 100.0: must exceed the last"},
  };
  for (const auto& [csv, fragment] : bad) {
    write("p1.csv", csv);
    try {
      read_case(file);
      ADD_FAILURE() << "no error for " << csv;
    } catch (const CaseError& e) {
      EXPECT_NE(std::string(e.what()).find(fragment), std::string::npos) << e.what();
    }
  }
  fs::remove(dir_ / "p1.csv");
  EXPECT_THROW(read_case(file), CaseError);
}

TEST_F(CaseFiles, EndlessFilesAreRefusedAtTheirByteLimit) {
  // /dev/zero never ends: as the case file, and as the duty-cycle CSV it names.
  try {
    read_case("/dev/zero");
    ADD_FAILURE() << "/dev/zero was read as a case";
  } catch (const CaseError& e) {
    EXPECT_NE(std::string(e.what()).find("/dev/zero: holds more than 16 MiB"), std::string::npos)
        << e.what();
  }
  const std::string text = replaced(
      mini_case,
      "segments = [ { start_s = 0.0, speed_rpm = 1000.0 }, { start_s = 50.0, speed_rpm = 0.0 } ]",
      "csv = \"/dev/zero\"");
  try {
    read_case(write("endless.toml", text));
    ADD_FAILURE() << "/dev/zero was read as a duty cycle";
  } catch (const CaseError& e) {
    EXPECT_NE(std::string(e.what()).find("duty_cycle.csv"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("more than 64 MiB"), std::string::npos) << e.what();
  }
}

TEST_F(CaseFiles, MissingCaseFileIsAnIoError) {
  EXPECT_THROW(read_case(dir_ / "absent.toml"), tt::core::IoError);
}
