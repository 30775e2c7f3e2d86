// The typed, validated case: what a case file says, in SI units, with defaults filled in.
// io/case_reader parses TOML into this once; nothing downstream sees the parse tree.
#pragma once

#include <Eigen/Core>
#include <array>
#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "core/limits.hpp"

namespace tt::core {

struct Material {
  std::string name;
  double density = 0;         /// [kg/m^3]
  double specific_heat = 0;   /// [J/(kg K)]
  double conductivity = 0;    /// [W/(m K)]
  double youngs_modulus = 0;  /// [Pa]
  double poisson_ratio = 0;   /// [-]
  double expansion = 0;       /// [1/K]
};

/// A solid primitive. Cylinders and annuli have their axis parallel to z.
struct Primitive {
  enum class Kind { box, cylinder, annulus, surface_file };
  Kind kind = Kind::box;
  Eigen::Vector3d min = Eigen::Vector3d::Zero();   /// box corner [m]
  Eigen::Vector3d max = Eigen::Vector3d::Zero();   /// box corner [m]
  Eigen::Vector2d axis = Eigen::Vector2d::Zero();  /// (x, y) of a cylinder's axis [m]
  double radius = 0;                               /// cylinder radius, annulus outer radius [m]
  double inner_radius = 0;                         /// annulus inner radius [m]
  double z_min = 0, z_max = 0;                     /// axial extent [m]
  std::filesystem::path file;  /// closed STL/OFF/PLY surface (flat convex polygons), case unit
  double file_scale = 1.0;     /// factor from the file's length unit to m
  std::string where;           /// where it was declared, for messages: "bodies[0].add[1]"
};

/// A solid body: union of `add` minus union of `subtract`; one material region of the mesh.
struct Body {
  std::string name;
  int material = -1;  /// index into CaseSpec::materials
  std::vector<Primitive> add;
  std::vector<Primitive> subtract;
  double max_edge = 0;  /// target tet edge length in this body [m]
};

/// One rule selecting mesh faces (all given conditions must hold).
struct FaceSelector {
  std::vector<int> bodies;  /// faces of tets in these bodies; empty: any body
  enum class Side { exterior, interface, any };
  Side side = Side::exterior;            /// exterior faces only, body interfaces only, or both
  std::vector<int> other_bodies;         /// with interface: the body across the face
  std::optional<Eigen::Vector4d> plane;  /// (n, d): faces in the plane n.x = d (n unit)
  struct Cylinder {
    Eigen::Vector2d axis;  /// (x, y) of the z-parallel axis [m]
    double radius;         /// [m]
  };
  std::optional<Cylinder> on_cylinder;  /// faces on that cylinder (within faceting tolerance)
  std::optional<Eigen::Vector3d> within_min, within_max;  /// face centroid inside this box [m]
};

/// A named set of boundary faces. `rest` groups take every face their selectors match that no
/// earlier non-rest group took ("all other faces").
struct BoundaryGroup {
  std::string name;
  std::vector<FaceSelector> select;  /// union of the selectors
  bool rest = false;
};

/// A named point that must be a mesh vertex at exactly its position.
struct NamedPoint {
  std::string id;
  Eigen::Vector3d position = Eigen::Vector3d::Zero();  /// [m]
  int on_group = -1;  /// boundary group it must lie on, -1 when not declared
};

struct MeshOptions {
  int order = 2;                   /// 1: 4-node, 2: 10-node tetrahedra
  int circle_segments = 48;        /// facets around every cylinder
  double radius_edge_ratio = 1.5;  /// TetGen quality bound
  double min_dihedral_deg = 12.0;  /// TetGen quality bound asked for
  /// Bounds on meshing (core/limits.hpp has the defaults): tetrahedra estimated before TetGen
  /// starts, TetGen's wall time [s] and the memory it may add [GB, 10^9 bytes].
  double max_tets = limits::kDefaultMaxTets;
  double time_limit_s = limits::kDefaultMeshTimeLimitS;
  double memory_limit_GB = limits::kDefaultMeshMemoryLimitGB;
};

/// Spindle speed over time: piecewise constant segments.
struct DutyCycle {
  struct Segment {
    double start = 0;      /// [s]
    double speed_rpm = 0;  /// spindle speed [rpm]
  };
  std::vector<Segment> segments;  /// start times ascending, first at 0
  double end = 0;                 /// [s]
  std::filesystem::path csv;      /// the CSV the segments were read from; empty when listed
};

/// A feed axis's motion over time: piecewise segments, each standing at `from` or reciprocating
/// between `from` and `to` at a constant feed speed (starting at `from`, towards `to`).
struct FeedAxis {
  struct Segment {
    double start = 0;         /// [s]
    double from = 0, to = 0;  /// positions along the axis [m]; from == to: standing
    double feed = 0;          /// feed speed [m/s]; 0: standing at `from`
  };
  std::string name;               /// "X"
  int direction = 0;              /// coordinate it moves along: 0 x, 1 y, 2 z
  std::vector<Segment> segments;  /// start times ascending, first at 0; empty: no feed axis
};

/// A time series sampled at points and linearly interpolated (constant outside).
struct TimeTable {
  std::vector<double> time;   /// [s]
  std::vector<double> value;  /// in the owner's SI unit
};

/// Heat generation uniform through a body's volume, following a law of spindle speed.
struct HeatSource {
  std::string name;
  int body = -1;
  enum class Law { speed_power, constant, palmgren, feed_power };
  Law law = Law::speed_power;
  double power_ref = 0;      /// [W] at ref_speed (speed_power) or always (constant)
  double ref_speed_rpm = 0;  /// [rpm]
  double exponent = 1.0;     /// Q = power_ref (n / ref_speed)^exponent, 0 at n = 0
  /// Palmgren: M = M0 + M1, M0 = 1e-7 f0 (nu n)^(2/3) dm^3 (nu n >= 2000), M1 = f1 P1 dm; Q = M w
  double palmgren_f0 = 0, palmgren_nu_cSt = 0, palmgren_dm = 0, palmgren_f1 = 0, palmgren_p1 = 0;
  double temperature_coefficient = 0;  /// [1/K]: Q multiplied by (1 + c (T_mean - T0))
  double ref_feed = 0;       /// [m/s] feed_power: Q = power_ref (v / ref_feed)^exponent, 0 at v = 0
  double window = 0;         /// [m] > 0: moves with the feed axis, only the body's part within
                             /// window/2 of (axis position + window_offset) is heated
  double window_offset = 0;  /// [m] window centre relative to the axis position
};

struct Convection {
  int group = -1;
  double h = 0;             /// [W/(m^2 K)] at standstill
  double h_speed_gain = 0;  /// [W/(m^2 K)]: h = h + gain (n / speed_ref)^speed_exponent
  double speed_ref_rpm = 1;
  double speed_exponent = 1;
  TimeTable sink;  /// sink temperature [degC] over time
};

struct SurfaceFlux {
  int group = -1;
  double flux = 0;             /// [W/m^2], into the body
  bool follows_speed = false;  /// scaled by n / ref_speed (speed_power law, exponent 1)
  double ref_speed_rpm = 0;
};

/// The time integrators the thermal stepper implements; the case reader refuses any other name.
enum class TimeScheme { backward_euler, crank_nicolson };

struct ThermalSpec {
  double initial_temperature_c = 20;  /// [degC]
  TimeScheme scheme = TimeScheme::backward_euler;
  double step = 12;             /// [s]
  double output_interval = 72;  /// [s]
  bool lumped_mass = false;
  std::vector<HeatSource> sources;
  std::vector<Convection> convection;
  std::vector<SurfaceFlux> fluxes;
};

/// A named point held in some directions (e.g. 3-2-1 supports against rigid motion only).
struct PointSupport {
  std::string point;                               /// id of a named point
  std::array<bool, 3> fixed = {true, true, true};  /// x, y, z
};

struct MechanicalSpec {
  bool enabled = true;
  std::vector<PointSupport> point_supports;
  double reference_temperature_c = 20;    /// stress-free temperature [degC]
  std::vector<int> fixed_groups;          /// boundary groups fixed in all directions
  std::string tcp_point;                  /// id of the tool centre point
  std::vector<std::string> probe_points;  /// ids of the two axial probe points (z1, z2)
  /// TCP error directions ("dx", "dy", "dz") that placement and fitting aim at, each on its own
  std::vector<std::string> targets = {"dy", "dz"};
  std::vector<std::string> axis_points;  /// ids of measurement points along the feed axis
  int axis_polynomial_degree = 3;        /// degree of the error polynomial in axis position
};

struct OutputSpec {
  std::vector<std::string> plot_points;  /// ids plotted in the temperature figure
  bool fields = true;                    /// write fields.pvd
  double fields_interval = 600;          /// time between field snapshots [s]
};

/// Where placement may put sensors ([placement] in the case file).
struct PlacementSpec {
  /// points: named points; surface: corner vertices of the mesh on chosen surfaces, plus the
  /// named points listed in `points`.
  enum class Candidates { points, surface };
  Candidates candidates = Candidates::points;
  /// points: the named points that are candidates; empty: every one but the TCP, the probe and
  /// the axis points. surface: named points added to the surface vertices.
  std::vector<std::string> points;
  std::vector<int> bodies;  /// surface: exterior faces of these bodies' tets
  std::vector<int> groups;  /// surface: faces of these boundary groups
  int max_candidates = 0;   /// surface: > 0 thins the vertices to this many, spread out
  /// The candidates are surface vertices (and their histories are candidate_temperatures.csv).
  bool surface() const { return candidates == Candidates::surface; }
};

struct CaseSpec {
  std::filesystem::path source;  /// the case file
  std::string name;
  std::string machine;  /// "SB-1" when it models the spec exactly
  std::uint64_t seed = 1;
  std::vector<Material> materials;
  std::vector<Body> bodies;
  std::vector<BoundaryGroup> groups;
  std::vector<NamedPoint> points;
  MeshOptions mesh;
  DutyCycle duty_cycle;
  FeedAxis feed_axis;
  ThermalSpec thermal;
  MechanicalSpec mechanical;
  OutputSpec outputs;
  PlacementSpec placement;
};

}  // namespace tt::core
