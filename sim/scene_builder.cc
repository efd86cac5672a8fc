#include "sim/scene_builder.h"

#include <Eigen/Geometry>

#include <algorithm>
#include <array>
#include <bit>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <set>
#include <sstream>

#include "common/errors.h"
#include "common/random_stream.h"
#include "common/units.h"

namespace airtwin {
namespace {

// Tracer collider: a disc of the footprint's radius, this high (m). Thin enough to sit inside the
// hemisphere, thick enough for cylinder-cylinder contacts between neighbours.
constexpr double kTracerColliderHeight = 0.004;
// Cotton wads do not roll: fibres snag and the wad is flat. Without rolling friction the
// composite's rounded hull rolled like a ball for some rest shapes (seeded), travelling a third
// farther than eq. (8) allows; condim 6 with a rolling-friction length of 3 cm (resisting torque
// <= 0.03 m x N, more than the air's ~0.015 m x mu N tipping moment) stops that, and the wads then
// follow eq. (8) like the tracers (docs/twin.md).
constexpr double kCottonTorsionalFriction = 0.005;  // m
constexpr double kCottonRollingFriction = 0.03;     // m
// Cotton composite: 3 x 3 x 3 grid -> 26 surface elements; element sphere radius as a fraction
// of the wad radius (the rest is the composite spacing).
constexpr int kCottonCount = 3;
constexpr double kCottonElementFraction = 0.36;
// Cotton wads i and i + 30 share a collision bit and would pass through each other.
constexpr int kCottonCollisionGroups = 30;
// Objects start this far above their resting height (m): a sub-millimetre drop.
constexpr double kDropHeight = 0.0002;

std::string num(double x) {
  char buffer[32];
  std::snprintf(buffer, sizeof(buffer), "%.9g", x);
  return buffer;
}

std::string where_object(const SceneSpec& spec, size_t i) {
  return spec.source + ": objects[" + std::to_string(i) + "] (id '" + spec.objects[i].id + "')";
}

void validate_type_parameters(const ObjectTypeParameters& p, const std::string& name) {
  auto positive = [&](double v, const char* field) {
    if (!(std::isfinite(v) && v > 0)) {
      throw InputError("scene parameters: " + name + "." + field + " must be > 0, got " + num(v));
    }
  };
  positive(p.diameter_m, "diameter_m");
  positive(p.mass_kg, "mass_kg");
  positive(p.drag_rate_per_s, "drag_rate_per_s");
  positive(p.stiction_speed_mps, "stiction_speed_mps");
  if (!(std::isfinite(p.kinetic_friction) && p.kinetic_friction >= 0)) {
    throw InputError("scene parameters: " + name + ".kinetic_friction must be >= 0, got " +
                     num(p.kinetic_friction));
  }
  if (!(std::isfinite(p.static_friction_ratio) && p.static_friction_ratio >= 1)) {
    throw InputError("scene parameters: " + name + ".static_friction_ratio must be >= 1, got " +
                     num(p.static_friction_ratio));
  }
  if (!(std::isfinite(p.extra_quadratic_drag_per_m) && p.extra_quadratic_drag_per_m >= 0)) {
    throw InputError("scene parameters: " + name +
                     ".extra_quadratic_drag_per_m must be >= 0, got " +
                     num(p.extra_quadratic_drag_per_m));
  }
  if (!(std::isfinite(p.extra_lift_s2pm2) && p.extra_lift_s2pm2 >= 0)) {
    throw InputError("scene parameters: " + name + ".extra_lift_s2pm2 must be >= 0, got " +
                     num(p.extra_lift_s2pm2));
  }
  if (!(std::isfinite(p.drag_intercept_share) && p.drag_intercept_share >= 0 &&
        p.drag_intercept_share < 1)) {
    throw InputError("scene parameters: " + name + ".drag_intercept_share must be in [0, 1), got " +
                     num(p.drag_intercept_share));
  }
  if (!(std::isfinite(p.air_gain) && p.air_gain >= 0)) {
    throw InputError("scene parameters: " + name + ".air_gain must be >= 0, got " +
                     num(p.air_gain));
  }
  if (!(std::isfinite(p.pressure_volume_m3) && p.pressure_volume_m3 >= 0)) {
    throw InputError("scene parameters: " + name + ".pressure_volume_m3 must be >= 0, got " +
                     num(p.pressure_volume_m3));
  }
}

// The tracer's visual mesh file, named in the MJCF and held in memory (or written beside an
// exported scene): binary STL, whose 32-bit floats MuJoCo reads exactly.
constexpr const char* kHemisphereFile = "hemisphere.stl";

// The closed hemisphere (dome + flat face) as binary STL: radius r, flat face at z = 0, triangles
// counter-clockwise seen from outside.
std::string hemisphere_stl(double r) {
  static_assert(std::endian::native == std::endian::little, "STL is little-endian");
  constexpr int kSegments = 24, kRings = 6;
  // Rings from the rim (ring 0, z = 0) up to just below the pole; then the pole and the centre of
  // the face.
  std::vector<Eigen::Vector3f> v;
  for (int k = 0; k < kRings; ++k) {
    const double elevation = 0.5 * kPi * k / kRings;
    for (int j = 0; j < kSegments; ++j) {
      const double azimuth = 2.0 * kPi * j / kSegments;
      v.emplace_back(static_cast<float>(r * std::cos(elevation) * std::cos(azimuth)),
                     static_cast<float>(r * std::cos(elevation) * std::sin(azimuth)),
                     static_cast<float>(r * std::sin(elevation)));
    }
  }
  const int pole = kRings * kSegments, centre = pole + 1;
  v.emplace_back(0.0f, 0.0f, static_cast<float>(r));
  v.emplace_back(0.0f, 0.0f, 0.0f);
  // Dome quads as two triangles each, the cap fan, the face.
  std::vector<std::array<int, 3>> f;
  for (int k = 0; k + 1 < kRings; ++k) {
    for (int j = 0; j < kSegments; ++j) {
      const int a = k * kSegments + j, b = k * kSegments + (j + 1) % kSegments;
      const int c = a + kSegments, d = b + kSegments;
      f.push_back({a, b, d});
      f.push_back({a, d, c});
    }
  }
  for (int j = 0; j < kSegments; ++j) {
    f.push_back(
        {(kRings - 1) * kSegments + j, (kRings - 1) * kSegments + (j + 1) % kSegments, pole});
  }
  for (int j = 0; j < kSegments; ++j) f.push_back({centre, (j + 1) % kSegments, j});
  // 80-byte header, triangle count, then per triangle: normal, three vertices, 2 spare bytes.
  std::string stl(80, '\0');
  const std::string header = "airtwin tracer: 3 cm hemisphere, flat face at z = 0, metres";
  stl.replace(0, header.size(), header);
  auto put = [&stl](const void* p, size_t n) { stl.append(static_cast<const char*>(p), n); };
  const uint32_t count = static_cast<uint32_t>(f.size());
  put(&count, 4);
  for (const auto& t : f) {
    const Eigen::Vector3f n = (v[t[1]] - v[t[0]]).cross(v[t[2]] - v[t[0]]).normalized();
    put(n.data(), 12);
    for (int i : t) put(v[i].data(), 12);
    stl.append(2, '\0');
  }
  return stl;
}

std::string tracer_body(size_t i, const ObjectSpec& o, double yaw, const ObjectTypeParameters& p) {
  const std::string name = "obj" + std::to_string(i);
  const double r = 0.5 * p.diameter_m, m = p.mass_kg;
  // Solid hemisphere about its centre of mass (3R/8 above the face): Ixx = 83/320 m R^2,
  // Izz = 2/5 m R^2.
  const double ixx = 83.0 / 320.0 * m * r * r, izz = 0.4 * m * r * r;
  std::ostringstream s;
  s << "<body name=\"" << name << "\" pos=\"" << num(o.p_W.x()) << ' ' << num(o.p_W.y()) << ' '
    << num(kDropHeight) << "\" euler=\"0 0 " << num(yaw) << "\">\n"
    << "  <freejoint name=\"" << name << "_free\"/>\n"
    << "  <inertial pos=\"0 0 " << num(3.0 / 8.0 * r) << "\" mass=\"" << num(m)
    << "\" diaginertia=\"" << num(ixx) << ' ' << num(ixx) << ' ' << num(izz) << "\"/>\n"
    << "  <geom name=\"" << name << "_collider\" class=\"collider\" type=\"cylinder\" size=\""
    << num(r) << ' ' << num(0.5 * kTracerColliderHeight) << "\" pos=\"0 0 "
    << num(0.5 * kTracerColliderHeight) << "\" friction=\"" << num(p.kinetic_friction)
    << " 0.005 0.0001\"/>\n"
    << "  <geom name=\"" << name << "_shell\" class=\"visual\" type=\"mesh\" mesh=\"hemisphere\""
    << " rgba=\"0.96 0.96 0.94 1\"/>\n"
    << "</body>\n";
  return s.str();
}

std::string cotton_body(size_t i, const ObjectSpec& o, double yaw, const ObjectTypeParameters& p) {
  const std::string name = "obj" + std::to_string(i);
  const double r = 0.5 * p.diameter_m;
  const double element_radius = kCottonElementFraction * r;
  const double spacing = r - element_radius;
  const int elements = kCottonCount * kCottonCount * kCottonCount;  // 26 surface + 1 centre
  // Collision masks: a wad's elements overlap their neighbours, so they must not collide with each
  // other, yet must collide with other wads, tracers and the floor (contype 1, conaffinity 1).
  // MuJoCo collides a pair when (contype_a & conaffinity_b) | (contype_b & conaffinity_a): wad i
  // gets its own bit as contype and every other bit (plus bit 0) as conaffinity.
  const unsigned own_bit = 1u << (1 + i % kCottonCollisionGroups);
  const unsigned affinity = (((1u << (kCottonCollisionGroups + 1)) - 1u) & ~own_bit) | 1u;
  std::ostringstream s;
  s << "<body name=\"" << name << "\" pos=\"" << num(o.p_W.x()) << ' ' << num(o.p_W.y()) << ' '
    << num(r + kDropHeight) << "\" euler=\"0 0 " << num(yaw) << "\">\n"
    << "  <freejoint name=\"" << name << "_free\"/>\n"
    << "  <composite type=\"ellipsoid\" count=\"" << kCottonCount << ' ' << kCottonCount << ' '
    << kCottonCount << "\" spacing=\"" << num(spacing) << "\" prefix=\"" << name << "_\">\n"
    << "    <geom type=\"sphere\" size=\"" << num(element_radius) << "\" mass=\""
    << num(p.mass_kg / elements) << "\" friction=\"" << num(p.kinetic_friction) << ' '
    << num(kCottonTorsionalFriction) << ' ' << num(kCottonRollingFriction)
    << "\" condim=\"6\" contype=\"" << own_bit << "\" conaffinity=\"" << affinity
    << "\" rgba=\"0.95 0.95 0.92 1\" group=\"3\"/>\n"
    << "    <joint kind=\"main\" stiffness=\"0.05\" damping=\"0.0005\"/>\n"
    << "    <skin rgba=\"0.95 0.95 0.92 1\" inflate=\"" << num(element_radius)
    << "\" subgrid=\"2\"/>\n"
    << "  </composite>\n"
    << "</body>\n";
  return s.str();
}

std::string rig_bodies(const SceneParameters& params) {
  std::ostringstream s;
  // XM430 servo cases (28.5 x 34 x 46.5 mm), the bracket, the nozzle (SMC KN-R02-250) and its
  // hose. The pan servo hangs from a rod that the top camera sees end-on.
  s << "<body name=\"nozzle_mount\" pos=\"0 0 " << num(params.nozzle_height_m) << "\">\n"
    << "  <geom class=\"visual\" type=\"cylinder\" fromto=\"0 0 0.10 0 0 1.0\" size=\"0.008\""
    << " material=\"rig_metal\"/>\n"
    << "  <body name=\"nozzle_pan\">\n"
    << "    <joint name=\"nozzle_pan\" type=\"hinge\" axis=\"0 0 1\" damping=\"1\"/>\n"
    << "    <inertial pos=\"0 0 0.07\" mass=\"0.08\" diaginertia=\"2e-5 2e-5 1e-5\"/>\n"
    << "    <geom class=\"visual\" type=\"box\" pos=\"0 0 0.0725\" size=\"0.0143 0.017 0.0233\""
    << " material=\"rig_servo\"/>\n"
    << "    <geom class=\"visual\" type=\"box\" pos=\"0 0.022 0.03\" size=\"0.012 0.002 0.03\""
    << " material=\"rig_metal\"/>\n"
    << "    <geom class=\"visual\" type=\"box\" pos=\"0 -0.022 0.03\" size=\"0.012 0.002 0.03\""
    << " material=\"rig_metal\"/>\n"
    << "    <body name=\"nozzle_tilt\">\n"
    << "      <joint name=\"nozzle_tilt\" type=\"hinge\" axis=\"0 -1 0\" damping=\"1\"/>\n"
    << "      <inertial pos=\"0 0 0.02\" mass=\"0.08\" diaginertia=\"2e-5 2e-5 1e-5\"/>\n"
    << "      <geom class=\"visual\" type=\"box\" pos=\"0 0 0.025\" size=\"0.0143 0.0170 0.0233\""
    << " material=\"rig_servo\"/>\n"
    << "      <geom class=\"visual\" type=\"cylinder\" fromto=\"0 0 0.0 0 0 0.03\" size=\"0.005\""
    << " material=\"rig_nozzle\"/>\n"
    << "      <geom class=\"visual\" type=\"cylinder\" fromto=\"0 0 0.03 0 0 0.12\" size=\"0.004\""
    << " material=\"rig_hose\"/>\n"
    << "      <site name=\"nozzle_exit\" pos=\"0 0 0\" size=\"0.003\"/>\n"
    << "    </body>\n"
    << "  </body>\n"
    << "</body>\n";
  return s.str();
}

// The draws that shape one cotton wad: per-axis extent factors and per-element radius factors.
struct CottonShape {
  double axis[3];
  double element[kCottonCount * kCottonCount * kCottonCount];
};

CottonShape draw_cotton_shape(uint64_t seed, size_t index, double irregularity) {
  RandomStream rng(seed, RandomPurpose::kShape, index);
  CottonShape shape;
  for (double& a : shape.axis) a = rng.uniform(1.0 - irregularity, 1.0 + irregularity);
  // A resting wad is flatter than it is wide.
  shape.axis[2] *= 0.6;
  for (double& e : shape.element)
    e = rng.uniform(1.0 - 0.5 * irregularity, 1.0 + 0.5 * irregularity);
  return shape;
}

double heading(const ObjectSpec& o, uint64_t seed, size_t index) {
  if (o.yaw_rad) return *o.yaw_rad;
  RandomStream rng(seed, RandomPurpose::kHeading, index);
  return rng.uniform(-kPi, kPi);
}

// Reshapes cotton wad `obj` (already indexed) in the compiled model and sets its resting height.
// Element rest positions are the element bodies' positions in the root frame.
void shape_cotton(mjModel* m, const SceneObject& obj, const CottonShape& shape,
                  double element_radius) {
  // The composite's central sphere is as big as the nominal wad and would turn it into a ball that
  // rolls: the surface elements carry all contacts.
  for (int g = m->body_geomadr[obj.root_body];
       g < m->body_geomadr[obj.root_body] + m->body_geomnum[obj.root_body]; ++g) {
    m->geom_contype[g] = 0;
    m->geom_conaffinity[g] = 0;
  }
  // The per-axis and per-element scaling of the rest shape.
  for (size_t k = 1; k < obj.bodies.size(); ++k) {
    const int b = obj.bodies[k];
    for (int a = 0; a < 3; ++a) {
      m->body_pos[3 * b + a] *= shape.axis[a] * shape.element[(k - 1) % std::size(shape.element)];
    }
  }
  // Resting height: the lowest element just touches the floor (the root turns only about z).
  double lowest = 0.0;
  for (size_t k = 1; k < obj.bodies.size(); ++k) {
    lowest = std::min(lowest, m->body_pos[3 * obj.bodies[k] + 2] - element_radius);
  }
  const int qadr = m->jnt_qposadr[m->body_jntadr[obj.root_body]];
  m->qpos0[qadr + 2] = -lowest + kDropHeight;
  m->body_pos[3 * obj.root_body + 2] = -lowest + kDropHeight;
}

// A wad's area shares from its element bodies' rest positions: a horizontal wind sees an element
// on the surface in proportion to the horizontal part of its outward normal, sqrt(1 - n_z^2)
// (averaged over wind directions); the centre element is shielded. False if no element is off
// the root's vertical axis (nothing for the wind to meet).
bool set_cotton_area_shares(const mjModel* m, SceneObject& obj) {
  obj.area_share.assign(obj.bodies.size(), 0.0);
  double total = 0.0;
  for (size_t k = 1; k < obj.bodies.size(); ++k) {
    const double* p = m->body_pos + 3 * obj.bodies[k];
    const double norm = std::sqrt(p[0] * p[0] + p[1] * p[1] + p[2] * p[2]);
    const double nz = norm > 0 ? p[2] / norm : 1.0;
    obj.area_share[k] = std::sqrt(std::max(0.0, 1.0 - nz * nz));
    total += obj.area_share[k];
  }
  if (!(total > 0)) return false;
  for (double& w : obj.area_share) w /= total;
  return true;
}

// Object i's compiled bodies: the subtree of body `obj<i>` (-1 and none if there is no such body).
SceneObject find_object(const mjModel* m, const SceneSpec& spec, size_t i) {
  SceneObject obj;
  obj.id = spec.objects[i].id;
  obj.type = parse_object_type(spec.objects[i].type, where_object(spec, i));
  obj.physics = spec.objects[i].physics;
  obj.root_body = mj_name2id(m, mjOBJ_BODY, object_body_name(i).c_str());
  if (obj.root_body < 0) return obj;
  for (int b = 0; b < m->nbody; ++b) {
    if (m->body_rootid[b] == obj.root_body) obj.bodies.push_back(b);
  }
  return obj;
}

// Shares and mass of an indexed object; false as set_cotton_area_shares.
bool finish_object(const mjModel* m, SceneObject& obj) {
  for (int b : obj.bodies) obj.mass_kg += m->body_mass[b];
  if (obj.type == ObjectType::kTracer) {
    obj.area_share = {1.0};
    return true;
  }
  return set_cotton_area_shares(m, obj);
}

// The objects of a scene this builder wrote, compiled into `m`, with the wads shaped from the
// seed: what export_scene writes (and so what build_scene simulates).
std::vector<SceneObject> shape_objects(mjModel* m, const SceneSpec& spec,
                                       const SceneParameters& params, uint64_t seed) {
  std::vector<SceneObject> objects;
  for (size_t i = 0; i < spec.objects.size(); ++i) {
    SceneObject obj = find_object(m, spec, i);
    AIRTWIN_DEMAND(obj.root_body > 0 && obj.bodies.front() == obj.root_body);
    if (obj.type == ObjectType::kTracer) {
      AIRTWIN_DEMAND(obj.bodies.size() == 1);
    } else {
      const double r = 0.5 * params.cotton.diameter_m;
      shape_cotton(m, obj, draw_cotton_shape(seed, i, params.cotton_irregularity),
                   kCottonElementFraction * r);
    }
    objects.push_back(std::move(obj));
  }
  return objects;
}

// In MuJoCo's written MJCF `xml`, switches off the collisions of geom `name` (contype and
// conaffinity 0): mj_saveLastXML copies numbers back from the model but not collision masks, and
// the wads' central spheres are switched off after compilation (shape_cotton).
void switch_off_collisions(std::string& xml, const std::string& name) {
  const std::string open = "<geom name=\"" + name + "\"";
  const size_t start = xml.find(open);
  AIRTWIN_DEMAND(start != std::string::npos);
  const size_t end = xml.find("/>", start);
  AIRTWIN_DEMAND(end != std::string::npos);
  std::string element = xml.substr(start, end - start);
  for (const std::string attribute : {" contype=\"", " conaffinity=\""}) {
    const size_t at = element.find(attribute);
    if (at != std::string::npos) {
      element.erase(at, element.find('"', at + attribute.size()) + 1 - at);
    }
  }
  element.insert(open.size(), " contype=\"0\" conaffinity=\"0\"");
  xml.replace(start, end - start, element);
}

}  // namespace

ObjectType parse_object_type(const std::string& name, const std::string& where) {
  if (name == "tracer") return ObjectType::kTracer;
  if (name == "cotton") return ObjectType::kCotton;
  throw InputError(where + ": unknown type '" + name + "', expected tracer or cotton");
}

void validate_scene(const SceneSpec& spec, const SceneParameters& params) {
  // The fixed parameters.
  if (!(std::isfinite(params.timestep_s) && params.timestep_s >= 1e-4 &&
        params.timestep_s <= 5e-3)) {
    throw InputError("scene parameters: timestep_s must be in [0.0001, 0.005], got " +
                     num(params.timestep_s));
  }
  if (!(std::isfinite(params.friction_impedance_ratio) && params.friction_impedance_ratio >= 1 &&
        params.friction_impedance_ratio <= 1000)) {
    throw InputError("scene parameters: friction_impedance_ratio must be in [1, 1000], got " +
                     num(params.friction_impedance_ratio));
  }
  for (double v : {params.floor_half_size_m, params.nozzle_height_m, params.camera_height_m,
                   params.camera_half_view_m}) {
    if (!(std::isfinite(v) && v > 0)) {
      throw InputError("scene parameters: sizes and heights must be > 0, got " + num(v));
    }
  }
  if (params.camera_resolution_px < 16) {
    throw InputError("scene parameters: camera_resolution_px must be >= 16");
  }
  if (!(std::isfinite(params.floor_slope_rad) && params.floor_slope_rad >= 0 &&
        params.floor_slope_rad <= kPi / 6)) {
    throw InputError("scene parameters: floor_slope_rad must be in [0, pi/6], got " +
                     num(params.floor_slope_rad));
  }
  if (!std::isfinite(params.floor_slope_direction_rad)) {
    throw InputError("scene parameters: floor_slope_direction_rad must be finite");
  }
  if (!(params.cotton_irregularity >= 0 && params.cotton_irregularity <= 0.5)) {
    throw InputError("scene parameters: cotton_irregularity must be in [0, 0.5], got " +
                     num(params.cotton_irregularity));
  }
  validate_type_parameters(params.tracer, "tracer");
  validate_type_parameters(params.cotton, "cotton");

  // Each object on its own: id, type, finite pose, footprint on the floor.
  std::vector<double> radius(spec.objects.size());
  std::set<std::string> ids;
  for (size_t i = 0; i < spec.objects.size(); ++i) {
    const ObjectSpec& o = spec.objects[i];
    const std::string where = where_object(spec, i);
    if (o.id.empty()) throw InputError(where + ": id must not be empty");
    if (!ids.insert(o.id).second) throw InputError(where + ": id is used twice");
    const ObjectType type = parse_object_type(o.type, where);
    if (!(std::isfinite(o.p_W.x()) && std::isfinite(o.p_W.y()))) {
      throw InputError(where + ": position must be finite, got (" + num(o.p_W.x()) + ", " +
                       num(o.p_W.y()) + ") m");
    }
    if (o.yaw_rad && !std::isfinite(*o.yaw_rad)) {
      throw InputError(where + ": yaw must be finite, got " + num(*o.yaw_rad));
    }
    if (o.physics) {
      validate_type_parameters(*o.physics, where + " physics");
      if (o.physics->diameter_m != params.of(type).diameter_m) {
        throw InputError(where + ": physics.diameter_m must be the " + o.type + "'s " +
                         num(params.of(type).diameter_m) + " m (the geometry is the type's), got " +
                         num(o.physics->diameter_m));
      }
    }
    radius[i] = 0.5 * params.of(type).diameter_m *
                (type == ObjectType::kCotton ? 1.0 + params.cotton_irregularity : 1.0);
    const double reach = std::max(std::abs(o.p_W.x()), std::abs(o.p_W.y())) + radius[i];
    if (reach > params.floor_half_size_m) {
      throw InputError(where + ": position (" + num(o.p_W.x()) + ", " + num(o.p_W.y()) +
                       ") m puts it outside the floor, which spans +-" +
                       num(params.floor_half_size_m) + " m");
    }
  }
  // Pairs: footprints must not overlap (a start inside another object explodes on contact).
  for (size_t i = 0; i < spec.objects.size(); ++i) {
    for (size_t j = i + 1; j < spec.objects.size(); ++j) {
      const double distance = (spec.objects[i].p_W - spec.objects[j].p_W).norm();
      if (distance < radius[i] + radius[j]) {
        throw InputError(where_object(spec, j) + ": overlaps objects[" + std::to_string(i) +
                         "] (id '" + spec.objects[i].id + "'): centres " + num(distance) +
                         " m apart, footprints need " + num(radius[i] + radius[j]) + " m");
      }
    }
  }
}

std::string scene_xml(const SceneSpec& spec, const SceneParameters& params, uint64_t seed) {
  validate_scene(spec, params);
  size_t n_tracers = 0, n_cotton = 0;
  for (const ObjectSpec& o : spec.objects) (o.type == "tracer" ? n_tracers : n_cotton)++;
  // Constraint buffers grow with the objects: a tracer uses a few contacts, a wad ~75 equality
  // rows plus its floor and neighbour contacts.
  const size_t njmax = 100 + 60 * n_tracers + 250 * n_cotton;
  const size_t nconmax = 50 + 12 * n_tracers + 40 * n_cotton;
  const double fovy_deg =
      rad_to_deg(2.0 * std::atan(params.camera_half_view_m / params.camera_height_m));
  const double h = params.floor_half_size_m;

  const Eigen::Vector3d gravity = params.gravity_W();

  std::ostringstream s;
  s << "<mujoco model=\"airtwin\">\n"
    << "<compiler angle=\"radian\" inertiafromgeom=\"auto\"/>\n"
    << "<option timestep=\"" << num(params.timestep_s) << "\" integrator=\""
    << (params.implicit_integrator ? "implicit" : "Euler") << "\" cone=\"elliptic\" impratio=\""
    << num(params.friction_impedance_ratio) << "\" gravity=\"" << num(gravity.x()) << ' '
    << num(gravity.y()) << ' ' << num(gravity.z()) << "\"/>\n"
    << "<size njmax=\"" << njmax << "\" nconmax=\"" << nconmax << "\"/>\n"
    << "<visual>\n"
    << "  <global offwidth=\"" << params.camera_resolution_px << "\" offheight=\""
    << params.camera_resolution_px << "\"/>\n"
    << "  <headlight ambient=\"0.35 0.35 0.35\" diffuse=\"0.4 0.4 0.4\"/>\n"
    << "</visual>\n"
    << "<default>\n"
    << "  <default class=\"visual\"><geom contype=\"0\" conaffinity=\"0\" group=\"1\""
    << " mass=\"0\"/></default>\n"
    << "  <default class=\"collider\"><geom group=\"3\" rgba=\"0.5 0.5 0.5 0\" condim=\"3\"/>"
    << "</default>\n"
    << "</default>\n"
    << "<asset>\n"
    << "  <texture name=\"floor_tex\" type=\"2d\" builtin=\"checker\" rgb1=\"0.34 0.36 0.39\""
    << " rgb2=\"0.30 0.32 0.35\" width=\"512\" height=\"512\"/>\n"
    << "  <material name=\"floor_mat\" texture=\"floor_tex\" texrepeat=\"" << num(h * 2) << ' '
    << num(h * 2) << "\" reflectance=\"0\"/>\n"
    << "  <material name=\"rig_metal\" rgba=\"0.6 0.6 0.62 1\"/>\n"
    << "  <material name=\"rig_servo\" rgba=\"0.1 0.1 0.1 1\"/>\n"
    << "  <material name=\"rig_nozzle\" rgba=\"0.75 0.7 0.4 1\"/>\n"
    << "  <material name=\"rig_hose\" rgba=\"0.2 0.4 0.8 1\"/>\n"
    << (n_tracers > 0
            ? std::string("  <mesh name=\"hemisphere\" file=\"") + kHemisphereFile + "\"/>\n"
            : std::string())
    << "</asset>\n"
    << "<worldbody>\n"
    << "  <light name=\"sun\" pos=\"0 0 4\" dir=\"0 0 -1\" directional=\"true\""
    << " diffuse=\"0.6 0.6 0.6\" castshadow=\"false\"/>\n"
    << "  <geom name=\"floor\" type=\"plane\" size=\"" << num(h) << ' ' << num(h)
    << " 0.05\" material=\"floor_mat\" friction=\"0 0 0\" condim=\"3\"/>\n"
    << "  <camera name=\"top\" pos=\"0 0 " << num(params.camera_height_m)
    << "\" xyaxes=\"1 0 0 0 1 0\" fovy=\"" << num(fovy_deg) << "\"/>\n"
    << rig_bodies(params);
  for (size_t i = 0; i < spec.objects.size(); ++i) {
    const ObjectSpec& o = spec.objects[i];
    const ObjectType type = parse_object_type(o.type, where_object(spec, i));
    const double yaw = heading(o, seed, i);
    const ObjectTypeParameters& physics = o.physics ? *o.physics : params.of(type);
    s << (type == ObjectType::kTracer ? tracer_body(i, o, yaw, physics)
                                      : cotton_body(i, o, yaw, physics));
  }
  s << "</worldbody>\n</mujoco>\n";
  return s.str();
}

std::vector<ModelFile> scene_files(const SceneSpec& spec, const SceneParameters& params) {
  for (const ObjectSpec& o : spec.objects) {
    if (o.type == "tracer") {
      return {{kHemisphereFile, hemisphere_stl(0.5 * params.tracer.diameter_m)}};
    }
  }
  return {};
}

std::string object_body_name(size_t i) { return "obj" + std::to_string(i); }

SceneExport export_scene(const SceneSpec& spec, const SceneParameters& params, uint64_t seed) {
  SceneExport out;
  out.files = scene_files(spec, params);
  std::vector<std::string> switched_off;
  out.xml =
      compiled_model_xml(scene_xml(spec, params, seed), spec.source, out.files, [&](mjModel* m) {
        for (const SceneObject& o : shape_objects(m, spec, params, seed)) {
          if (o.type != ObjectType::kCotton) continue;
          const int g0 = m->body_geomadr[o.root_body];
          for (int g = g0; g < g0 + m->body_geomnum[o.root_body]; ++g) {
            if (m->geom_contype[g] == 0 && m->geom_conaffinity[g] == 0) {
              switched_off.push_back(mj_id2name(m, mjOBJ_GEOM, g));
            }
          }
        }
      });
  for (const std::string& name : switched_off) switch_off_collisions(out.xml, name);
  return out;
}

namespace {

// Indexes a compiled scene's rig and objects (`scene.model`), checking first that it has what the
// twin looks up; `where` names the MJCF in messages.
void index_scene(BuiltScene& scene, const SceneSpec& spec, const SceneParameters& params,
                 const std::string& where) {
  const mjModel* m = scene.model.get();
  auto fail = [&](const std::string& what, const std::string& expected) {
    throw InputError(where + ": " + what + "; expected " + expected);
  };

  // The clocks of the servos, the delay line and the camera count in the twin's steps.
  if (m->opt.timestep != params.timestep_s) {
    fail("option timestep is " + num(m->opt.timestep) + " s",
         num(params.timestep_s) +
             " s, the twin's step (its servo, delay and camera clocks count in steps)");
  }
  // A scene file keeps its own integrator; asked for the implicit one, the file must have it.
  if (params.implicit_integrator && m->opt.integrator != mjINT_IMPLICIT) {
    fail("option integrator is not implicit",
         "integrator=\"implicit\" in its <option>, as the scene parameters ask");
  }
  // The rig's joints, set from the servo model every step, and the renderers' camera.
  for (const std::string joint : {"nozzle_pan", "nozzle_tilt"}) {
    const int j = mj_name2id(m, mjOBJ_JOINT, joint.c_str());
    if (j < 0 || m->jnt_type[j] != mjJNT_HINGE) {
      fail("joint '" + joint + (j < 0 ? "' not found" : "' is not a hinge"),
           "a hinge named '" + joint + "' (the nozzle's " +
               (joint == "nozzle_pan" ? "pan" : "tilt") + " servo)");
    }
  }
  scene.pan_joint = mj_name2id(m, mjOBJ_JOINT, "nozzle_pan");
  scene.tilt_joint = mj_name2id(m, mjOBJ_JOINT, "nozzle_tilt");
  if (mj_name2id(m, mjOBJ_CAMERA, "top") < 0) {
    fail("camera 'top' not found",
         "a camera named 'top' (the rig's top camera, which the renders and vision use)");
  }
  // The objects: obj<i> per object of the scenario, and no more.
  for (size_t i = 0; i < spec.objects.size(); ++i) {
    const std::string name = object_body_name(i);
    const std::string what = "body '" + name + "' (" + spec.objects[i].type + " '" +
                             spec.objects[i].id + "', objects[" + std::to_string(i) +
                             "] of the scenario)";
    const std::string expected_body =
        "a body named '" + name + "' on the world body with a free joint as its first joint";
    SceneObject obj = find_object(m, spec, i);
    if (obj.root_body < 0) fail(what + " not found", expected_body);
    const int b = obj.root_body;
    if (m->body_parentid[b] != 0) fail(what + " is not on the world body", expected_body);
    if (m->body_jntnum[b] < 1 || m->jnt_type[m->body_jntadr[b]] != mjJNT_FREE) {
      fail(what + " has no free joint as its first joint", expected_body);
    }
    if (obj.type == ObjectType::kTracer && obj.bodies.size() != 1) {
      fail(what + " has " + std::to_string(obj.bodies.size()) + " bodies",
           "a tracer to be one body");
    }
    if (obj.type == ObjectType::kCotton && obj.bodies.size() < 2) {
      fail(what + " has no element bodies", "a wad's element bodies under it");
    }
    if (obj.bodies.size() > kMaxObjectBodies) {
      fail(what + " has " + std::to_string(obj.bodies.size()) + " bodies",
           "at most " + std::to_string(kMaxObjectBodies) + " bodies per object");
    }
    if (!finish_object(m, obj)) {
      fail(what + ": its element bodies all lie on its vertical axis",
           "a wad's element bodies around its centre (the air meets them by their horizontal "
           "area)");
    }
    scene.objects.push_back(std::move(obj));
  }
  const std::string extra = object_body_name(spec.objects.size());
  if (mj_name2id(m, mjOBJ_BODY, extra.c_str()) >= 0) {
    fail("body '" + extra + "' has no object in the scenario (" +
             std::to_string(spec.objects.size()) + " objects)",
         spec.objects.empty()
             ? std::string("no object bodies")
             : "object bodies obj0 to " + object_body_name(spec.objects.size() - 1) + " only");
  }
}

}  // namespace

BuiltScene build_scene(const SceneSpec& spec, const SceneParameters& params, uint64_t seed) {
  // The twin compiles the exported text, so that a scene written by `export_scene` is, by
  // construction, what the twin simulates.
  SceneExport mjcf = export_scene(spec, params, seed);
  BuiltScene scene;
  scene.model = load_model_from_xml(mjcf.xml, spec.source, mjcf.files);
  scene.xml = std::move(mjcf.xml);
  index_scene(scene, spec, params, spec.source);
  return scene;
}

BuiltScene load_scene(const std::string& path, const SceneSpec& spec,
                      const SceneParameters& params) {
  validate_scene(spec, params);
  BuiltScene scene;
  scene.model = load_model_from_file(path);
  std::ifstream in(path, std::ios::binary);
  std::ostringstream text;
  text << in.rdbuf();
  scene.xml = text.str();
  index_scene(scene, spec, params, path);
  return scene;
}

const ObjectTypeParameters& physics_of(const SceneObject& object, const SceneParameters& params) {
  return object.physics ? *object.physics : params.of(object.type);
}

}  // namespace airtwin
