// The SDF importer (kelp/sim/vehicle_file.hpp, docs/vehicle-files.md): a Gazebo (gz-sim) model's
// body link, Hydrodynamics, Thruster and Buoyancy systems into a kelp VehicleDescription.
//
// Frames and signs (gz-sim src/systems/hydrodynamics/Hydrodynamics.cc and
// src/systems/thruster/Thruster.cc, gz-sim 7/8; include/gz/sim/Link.hh):
// - Gazebo's link frame is x forward, y left, z up (FLU); kelp's body frame FRD. With
//   S = diag(1, −1, −1): r_FRD = S r_FLU, I_FRD = S I S, and for 6-vectors (force, moment) and
//   6×6 matrices T = diag(S, S): A_FRD = T A T.
// - Hydrodynamics applies, at the link origin (Link::AddWorldWrench), the wrench
//   Ma ν̇ + C ν + Σ_j (L_ij + Σ_k Qabs_ijk |ν_k| + Q_ijk ν_k) ν_j, with ν the link origin's velocity
//   relative to the current in the link frame, Ma(i, j) = <iDotJ>, L(i, j) = <iJ>,
//   Qabs(i, j, k) = <iJabsK> and Q(i, j, k) = <iJK> (i in xyzkmn, j and k in UVWPQR). Stable
//   coefficients are negative, so kelp's positive magnitudes are M_A = −T Ma T, D_L = −T L T and
//   d_i = −Qabs(i, i, i) (unchanged by T: T_i² = 1).
// - Thruster applies thrust along R_joint·axis (the joint's pose in its child link's frame) at
//   the child link's origin; thrust = Ct ρ D⁴ |ω| ω.
#include <tinyxml2.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <iterator>
#include <map>
#include <set>
#include <sstream>

#include "kelp/sim/scenario_reader.hpp"
#include "kelp/sim/vehicle_file.hpp"
#include "vehicle_check.hpp"

namespace kelp {
namespace sim {

namespace {

using tinyxml2::XMLElement;
using Matrix6d = Matrix6<double>;

// A frame's pose in another: p_a = R p_b + t.
struct Pose {
  Eigen::Matrix3d R = Eigen::Matrix3d::Identity();
  Eigen::Vector3d t = Eigen::Vector3d::Zero();
  Pose operator*(const Pose& b) const { return {R * b.R, t + R * b.t}; }
  Pose inverse() const { return {R.transpose(), -(R.transpose() * t)}; }
};

const Eigen::Matrix3d kS = Eigen::Vector3d(1, -1, -1).asDiagonal();  // FLU ↔ FRD

std::string name_of(const XMLElement* e) {
  const char* n = e->Attribute("name");
  return n ? n : "";
}

// The kind of a plugin from its file name: "hydrodynamics", "thruster", "buoyancy" for
// gz-sim's (gz-sim[N]-…-system) and Ignition Gazebo's (ignition-gazebo[N]-…-system) systems,
// with or without lib… .so; else "".
std::string gazebo_system(std::string f) {
  if (f.rfind("lib", 0) == 0) f = f.substr(3);
  if (f.size() > 3 && f.compare(f.size() - 3, 3, ".so") == 0) f.resize(f.size() - 3);
  std::size_t i;
  if (f.rfind("gz-sim", 0) == 0) {
    i = 6;
  } else if (f.rfind("ignition-gazebo", 0) == 0) {
    i = 15;
  } else {
    return "";
  }
  while (i < f.size() && std::isdigit(static_cast<unsigned char>(f[i]))) ++i;
  const std::string rest = f.substr(i);
  for (const char* kind : {"hydrodynamics", "thruster", "buoyancy"})
    if (rest == std::string("-") + kind + "-system") return kind;
  return "";
}

class SdfReader {
 public:
  SdfReader(std::string file, const SdfImportOptions& o) : file_(std::move(file)), o_(o) {}

  SdfImport read(const std::string& text) {
    tinyxml2::XMLDocument doc;
    if (doc.Parse(text.c_str(), text.size()) != tinyxml2::XML_SUCCESS)
      fail("", std::string("malformed XML: ") + doc.ErrorStr());
    const XMLElement* root = doc.RootElement();
    if (root == nullptr || std::string(root->Name()) != "sdf")
      fail("", "expected an <sdf> root element");
    model_ = root->FirstChildElement("model");
    if (model_ == nullptr) fail("/sdf", "no <model>");
    mpath_ = "/sdf/model[" + name_of(model_) + "]";
    for (const XMLElement* l = model_->FirstChildElement("link"); l;
         l = l->NextSiblingElement("link"))
      links_[name_of(l)] = l;
    for (const XMLElement* j = model_->FirstChildElement("joint"); j;
         j = j->NextSiblingElement("joint"))
      joints_[name_of(j)] = j;
    for (const char* e : {"include", "model"})
      for (const XMLElement* m = model_->FirstChildElement(e); m; m = m->NextSiblingElement(e))
        note("<" + std::string(e) + "> " + name_of(m) +
             " (a nested model) is not imported: kelp reads one model's links");

    body_ = o_.link.empty() ? model_->FirstChildElement("link") : find_link(o_.link, mpath_);
    if (body_ == nullptr) fail(mpath_, "no <link>");
    body_name_ = name_of(body_);
    bpath_ = mpath_ + "/link[" + body_name_ + "]";
    X_mb_ = link_pose(body_name_, 0);

    VehicleDescription& d = out_.vehicle;
    d.name = name_of(model_).empty() ? "sdf model" : name_of(model_);
    d.attachment = o_.attachment;
    d.parameters.gravity = o_.gravity_m_s2;
    inertial();
    for (const XMLElement* p = model_->FirstChildElement("plugin"); p;
         p = p->NextSiblingElement("plugin"))
      plugin(p, mpath_);
    for (const XMLElement* p = body_->FirstChildElement("plugin"); p;
         p = p->NextSiblingElement("plugin"))
      plugin(p, bpath_);
    d.parameters.density = buoyancy_density_ > 0 ? buoyancy_density_
                           : water_density_ > 0  ? water_density_
                                                 : o_.density_kg_m3;
    collisions();
    thrusters_done();
    for (const auto& l : links_)
      if (l.second != body_ && !thruster_links_.count(l.first)) other_link(l.second);
    for (const auto& j : joints_)
      if (!thruster_joints_.count(j.first))
        note("joint " + j.first + " is not carried: kelp's vehicle is one rigid body");
    return std::move(out_);
  }

 private:
  [[noreturn]] void fail(const std::string& path, const std::string& what) const {
    throw scenario_error(file_ + ": " + (path.empty() ? "/" : path) + ": " + what);
  }
  void note(const std::string& s) { out_.not_carried.push_back(s); }

  double number(const char* text, const std::string& path) const {
    if (text == nullptr) fail(path, "expected a number, got nothing");
    char* end = nullptr;
    const double x = std::strtod(text, &end);
    while (end && *end && std::isspace(static_cast<unsigned char>(*end))) ++end;
    if (end == text || (end && *end) || !std::isfinite(x) || std::abs(x) > 1e12)
      fail(path, std::string("expected a finite number, got \"") + text + "\"");
    return x;
  }
  // The number of child element `key` of `e`, or `fallback` when there is none.
  double child_number(const XMLElement* e, const char* key, const std::string& path,
                      double fallback) const {
    const XMLElement* c = e->FirstChildElement(key);
    return c ? number(c->GetText(), path + "/" + key) : fallback;
  }
  std::vector<double> numbers(const char* text, const std::string& path, std::size_t n) const {
    std::istringstream in(text ? text : "");
    std::vector<double> v;
    std::string tok;
    while (in >> tok) v.push_back(number(tok.c_str(), path));
    if (v.size() != n)
      fail(path, "expected " + std::to_string(n) + " numbers, got \"" + (text ? text : "") + "\"");
    return v;
  }
  bool boolean(const XMLElement* e, const char* key, const std::string& path) const {
    const XMLElement* c = e->FirstChildElement(key);
    if (c == nullptr) return false;
    const std::string t = c->GetText() ? c->GetText() : "";
    if (t == "true" || t == "1") return true;
    if (t == "false" || t == "0") return false;
    fail(path + "/" + key, "expected true or false, got \"" + t + "\"");
  }

  // <pose> (x y z roll pitch yaw, radians; degrees="true" allowed): R = Rz(yaw) Ry(pitch)
  // Rx(roll), gz::math's Euler convention.
  Pose pose(const XMLElement* e, const std::string& path) const {
    Pose p;
    const XMLElement* q = e->FirstChildElement("pose");
    if (q == nullptr) return p;
    const char* fmt = q->Attribute("rotation_format");
    if (fmt && std::string(fmt) != "euler_rpy")
      fail(path + "/pose", "only rotation_format=\"euler_rpy\" is supported");
    const std::vector<double> v = numbers(q->GetText(), path + "/pose", 6);
    const double k = q->BoolAttribute("degrees", false) ? M_PI / 180.0 : 1.0;
    p.t = Eigen::Vector3d(v[0], v[1], v[2]);
    p.R = (Eigen::AngleAxisd(k * v[5], Eigen::Vector3d::UnitZ()) *
           Eigen::AngleAxisd(k * v[4], Eigen::Vector3d::UnitY()) *
           Eigen::AngleAxisd(k * v[3], Eigen::Vector3d::UnitX()))
              .toRotationMatrix();
    return p;
  }
  const char* relative_to(const XMLElement* e) const {
    const XMLElement* q = e->FirstChildElement("pose");
    return q ? q->Attribute("relative_to") : nullptr;
  }

  const XMLElement* find_link(const std::string& name, const std::string& path) const {
    const auto it = links_.find(name);
    if (it == links_.end()) fail(path, "no <link name=\"" + name + "\">");
    return it->second;
  }
  // A frame's pose in the model frame: "__model__" or a link (links may be posed relative to
  // other links).
  Pose frame_pose(const std::string& frame, int depth, const std::string& path) const {
    if (frame.empty() || frame == "__model__") return Pose{};
    if (!links_.count(frame))
      fail(path, "relative_to=\"" + frame + "\": only the model and its links are supported");
    return link_pose(frame, depth + 1);
  }
  Pose link_pose(const std::string& name, int depth) const {
    const std::string path = mpath_ + "/link[" + name + "]";
    if (depth > 32) fail(path + "/pose", "relative_to forms a cycle");
    const XMLElement* l = find_link(name, mpath_);
    const char* rel = relative_to(l);
    return frame_pose(rel ? rel : "", depth, path + "/pose") * pose(l, path);
  }

  void inertial() {
    const std::string path = bpath_ + "/inertial";
    const XMLElement* in = body_->FirstChildElement("inertial");
    if (in == nullptr) fail(path, "missing: the body link needs its mass and inertia");
    if (in->FirstChildElement("mass") == nullptr) fail(path + "/mass", "missing");
    const double m = child_number(in, "mass", path, 0.0);
    if (!(m > 0.0)) fail(path + "/mass", "expected a positive mass, got " + std::to_string(m));
    const XMLElement* I = in->FirstChildElement("inertia");
    if (I == nullptr) fail(path + "/inertia", "missing");
    const std::string ip = path + "/inertia";
    for (const char* k : {"ixx", "iyy", "izz"})
      if (I->FirstChildElement(k) == nullptr) fail(ip + "/" + k, "missing");
    const double ixx = child_number(I, "ixx", ip, 0), iyy = child_number(I, "iyy", ip, 0),
                 izz = child_number(I, "izz", ip, 0), ixy = child_number(I, "ixy", ip, 0),
                 ixz = child_number(I, "ixz", ip, 0), iyz = child_number(I, "iyz", ip, 0);
    Eigen::Matrix3d inertia;
    inertia << ixx, ixy, ixz, ixy, iyy, iyz, ixz, iyz, izz;
    const char* rel = relative_to(in);
    if (rel && std::string(rel) != body_name_)
      fail(path + "/pose", "only an inertial pose relative to its link is supported");
    const Pose p = pose(in, path);
    vehicle::VehicleParameters<double>& v = out_.vehicle.parameters;
    v.mass = m;
    v.inertia = kS * (p.R * inertia * p.R.transpose()) * kS;
    v.r_g = kS * p.t;
  }

  void plugin(const XMLElement* p, const std::string& parent) {
    const char* f = p->Attribute("filename");
    const std::string file = f ? f : "";
    const std::string path = parent + "/plugin[" + file + "]";
    const std::string kind = gazebo_system(file);
    if (kind == "hydrodynamics") {
      hydrodynamics(p, path);
    } else if (kind == "thruster") {
      thruster(p, path);
    } else if (kind == "buoyancy") {
      buoyancy(p, path);
    } else {
      note("plugin " + file + " (" + name_of(p) +
           ") is not a Gazebo system kelp imports (Hydrodynamics, Thruster, Buoyancy): ignored");
    }
  }

  void hydrodynamics(const XMLElement* p, const std::string& path) {
    static const char* moment = "xyzkmn";
    static const char* vel = "UVWPQR";
    Matrix6d Ma = Matrix6d::Zero(), L = Matrix6d::Zero();
    double Qabs[6][6][6] = {}, Q[6][6][6] = {};
    std::map<std::string, double*> coefficient;
    for (int i = 0; i < 6; ++i)
      for (int j = 0; j < 6; ++j) {
        const std::string ij = std::string(1, moment[i]) + vel[j];
        coefficient[std::string(1, moment[i]) + "Dot" + vel[j]] = &Ma(i, j);
        coefficient[ij] = &L(i, j);
        for (int k = 0; k < 6; ++k) {
          coefficient[ij + "abs" + vel[k]] = &Qabs[i][j][k];
          coefficient[ij + vel[k]] = &Q[i][j][k];
        }
      }
    bool disable_added_mass = false;
    for (const XMLElement* c = p->FirstChildElement(); c; c = c->NextSiblingElement()) {
      const std::string key = c->Name();
      const std::string cp = path + "/" + key;
      const auto it = coefficient.find(key);
      if (it != coefficient.end()) {
        *it->second = number(c->GetText(), cp);
      } else if (key == "water_density") {
        water_density_ = number(c->GetText(), cp);
        if (!(water_density_ > 0)) fail(cp, "expected a positive density");
      } else if (key == "link_name") {
        const std::string l = c->GetText() ? c->GetText() : "";
        if (l != body_name_) {
          note("Hydrodynamics acts on link " + l + ", not on the body link " + body_name_ +
               ": not imported");
          return;
        }
      } else if (key == "default_current") {
        if (Eigen::Map<const Eigen::Vector3d>(numbers(c->GetText(), cp, 3).data()).norm() > 0)
          note(
              "Hydrodynamics <default_current> is not carried: the current is the "
              "environment's in kelp (scenario or environment::Current)");
      } else if (key == "disable_coriolis") {
        if (boolean(p, "disable_coriolis", path))
          note("Hydrodynamics <disable_coriolis>: kelp always has the added-mass Coriolis");
      } else if (key == "disable_added_mass") {
        disable_added_mass = boolean(p, "disable_added_mass", path);
        if (disable_added_mass)
          note("Hydrodynamics <disable_added_mass>: the added mass is not imported");
      } else if (key != "namespace") {
        note("Hydrodynamics <" + key + "> is not carried");
      }
    }
    Matrix6d T = Matrix6d::Zero();
    T.topLeftCorner<3, 3>() = kS;
    T.bottomRightCorner<3, 3>() = kS;
    vehicle::VehicleParameters<double>& v = out_.vehicle.parameters;
    // (+ 0.0 turns the −0 of a negated zero into +0.)
    if (!disable_added_mass) v.added_mass = (-(T * Ma * T)).array() + 0.0;
    v.damping.linear = (-(T * L * T)).array() + 0.0;
    for (int i = 0; i < 6; ++i) v.damping.quadratic(i) = -Qabs[i][i][i] + 0.0;
    for (int i = 0; i < 6; ++i)
      for (int j = 0; j < 6; ++j)
        for (int k = 0; k < 6; ++k) {
          const std::string ij = std::string(1, moment[i]) + vel[j];
          if (Qabs[i][j][k] != 0.0 && !(i == j && j == k))
            note("Hydrodynamics <" + ij + "abs" + vel[k] +
                 ">: kelp's quadratic damping is diagonal (d_i |nu_i| nu_i)");
          if (Q[i][j][k] != 0.0)
            note("Hydrodynamics <" + ij + vel[k] +
                 ">: a signed quadratic term (nu_j nu_k, not |nu_k| nu_j) is not carried");
        }
    if (!disable_added_mass && !Ma.isZero(0.0)) {
      note(
          "Hydrodynamics: Gazebo's added-mass Coriolis uses only the diagonal of the added "
          "mass; kelp's uses the whole M_A (Fossen 2021, C_A = m2c(M_A, nu_r))");
      note(
          "Hydrodynamics: Gazebo applies the added-mass force from the previous step's "
          "acceleration; kelp puts M_A in the mass matrix");
    }
  }

  void buoyancy(const XMLElement* p, const std::string& path) {
    if (const XMLElement* u = p->FirstChildElement("uniform_fluid_density")) {
      buoyancy_density_ = number(u->GetText(), path + "/uniform_fluid_density");
    } else if (const XMLElement* g = p->FirstChildElement("graded_buoyancy")) {
      buoyancy_density_ = child_number(g, "default_density", path + "/graded_buoyancy", 0.0);
      note(
          "Buoyancy <graded_buoyancy>: the density layers are not carried (the default "
          "density is; kelp's free surface comes from the hydrostatics model)");
    }
    if (!(buoyancy_density_ > 0) &&
        (p->FirstChildElement("uniform_fluid_density") || p->FirstChildElement("graded_buoyancy")))
      fail(path, "expected a positive fluid density");
  }

  void thruster(const XMLElement* p, const std::string& path) {
    const XMLElement* jn = p->FirstChildElement("joint_name");
    if (jn == nullptr || jn->GetText() == nullptr) fail(path + "/joint_name", "missing");
    const std::string joint = jn->GetText();
    const auto jt = joints_.find(joint);
    if (jt == joints_.end()) fail(path + "/joint_name", "no <joint name=\"" + joint + "\">");
    const XMLElement* j = jt->second;
    const std::string jpath = mpath_ + "/joint[" + joint + "]";
    const XMLElement* child = j->FirstChildElement("child");
    if (child == nullptr || child->GetText() == nullptr) fail(jpath + "/child", "missing");
    const std::string cname = child->GetText();
    const XMLElement* clink = find_link(cname, jpath + "/child");
    const Pose X_mc = link_pose(cname, 0);
    // The joint's pose: in its child link's frame unless relative_to says otherwise.
    const char* rel = relative_to(j);
    const Pose X_mj = (rel ? frame_pose(rel, 0, jpath + "/pose") : X_mc) * pose(j, jpath);
    const XMLElement* axis = j->FirstChildElement("axis");
    if (axis == nullptr) fail(jpath + "/axis", "missing");
    const XMLElement* xyz = axis->FirstChildElement("xyz");
    if (xyz == nullptr) fail(jpath + "/axis/xyz", "missing");
    const std::vector<double> a = numbers(xyz->GetText(), jpath + "/axis/xyz", 3);
    Eigen::Vector3d ax(a[0], a[1], a[2]);
    if (!(ax.norm() > 1e-12)) fail(jpath + "/axis/xyz", "expected a non-zero axis");
    const char* in = xyz->Attribute("expressed_in");
    const bool in_model = (in && std::string(in) == "__model__") ||
                          boolean(axis, "use_parent_model_frame", jpath + "/axis");
    if (in && !in_model) {
      if (!links_.count(in))
        fail(jpath + "/axis/xyz", "expressed_in=\"" + std::string(in) + "\": not supported");
      ax = link_pose(in, 0).R * ax;
    } else if (!in_model) {
      ax = X_mj.R * ax;
    }
    ax.normalize();

    double ct = 1.0;
    if (const XMLElement* c = p->FirstChildElement("thrust_coefficient")) {
      ct = number(c->GetText(), path + "/thrust_coefficient");
    } else if (p->FirstChildElement("alpha_1")) {
      ct = child_number(p, "alpha_1", path, 1.0);
      note("Thruster " + joint +
           ": the thrust coefficient's advance-ratio term (alpha_2, "
           "wake_fraction) is not carried; Ct = alpha_1");
    } else {
      note("Thruster " + joint + ": no <thrust_coefficient>: Gazebo's default 1 is used");
    }
    const double rho = child_number(p, "fluid_density", path, 1000.0);
    const double dia = child_number(p, "propeller_diameter", path, 0.02);
    if (!(rho > 0) || !(dia > 0) || ct == 0.0)
      fail(path,
           "expected a positive fluid_density and propeller_diameter and a non-zero "
           "thrust_coefficient");
    const bool angvel = boolean(p, "use_angvel_cmd", path);
    const double k = std::abs(ct) * rho * std::pow(dia, 4);
    const double cmd_max = child_number(p, "max_thrust_cmd", path, 1000.0);
    const double cmd_min = child_number(p, "min_thrust_cmd", path, -1000.0);
    double w_max = o_.max_propeller_speed_rad_s;
    std::string source = "SdfImportOptions::max_propeller_speed_rad_s";
    if (!(w_max > 0)) {
      const XMLElement* lim = axis->FirstChildElement("limit");
      const double v = lim ? child_number(lim, "velocity", jpath + "/axis/limit", -1.0) : -1.0;
      if (v > 0) {
        w_max = v;
        source = "the joint's <limit><velocity>";
      } else if (p->FirstChildElement("max_thrust_cmd")) {
        w_max = angvel ? cmd_max : std::sqrt(std::max(cmd_max, 0.0) / k);
        source = "<max_thrust_cmd>";
      }
    }
    if (!(w_max > 0) || !std::isfinite(w_max))
      fail(path,
           "cannot normalise the thruster's command: give its joint an <axis><limit>"
           "<velocity>, the plugin a <max_thrust_cmd> or SdfImportOptions::"
           "max_propeller_speed_rad_s");
    char speed[32];
    std::snprintf(speed, sizeof speed, "%g", w_max);
    note("Thruster " + joint + ": command u in [-1, 1] is the propeller speed u*" + speed +
         " rad/s (from " + source + "); thrust Ct rho D^4 |omega| omega is tabulated at " +
         std::to_string(o_.curve_points) + " commands; it draws no current from the battery");
    // Force commands: thrust along the axis (Ct's sign only turns the propeller the other way);
    // speed commands: Ct's sign turns the thrust.
    const Eigen::Vector3d dir = (angvel && ct < 0) ? Eigen::Vector3d(-ax) : ax;
    vehicle::ThrustCurve curve;  // no currents: Gazebo's Thruster has no electrical model
    const int n = o_.curve_points;
    if (n < 3 || n % 2 == 0 || n > vehicle::max_curve_points)
      throw invalid_argument("SdfImportOptions::curve_points must be odd, in [3, " +
                             std::to_string(vehicle::max_curve_points - 1) + "]");
    curve.command.resize(n);
    curve.thrust.resize(n);
    for (int i = 0; i < n; ++i) {
      const double u = i == n - 1 ? 1.0 : -1.0 + 2.0 * i / (n - 1);
      double w = u * w_max;
      if (angvel) w = std::min(std::max(w, cmd_min), cmd_max);
      double f = k * std::abs(w) * w;
      if (!angvel) f = std::min(std::max(f, cmd_min), cmd_max);
      curve.command(i) = u;
      curve.thrust(i) = f;
    }
    // In the body link's frame, then FRD.
    const Pose X_bm = X_mb_.inverse();
    Thruster t;
    t.position = kS * (X_bm.R * X_mc.t + X_bm.t);
    t.direction = kS * (X_bm.R * dir);
    t.curve = curve;
    thrusters_.push_back(t);
    thruster_links_.insert(cname);
    thruster_joints_.insert(joint);
    const XMLElement* ci = clink->FirstChildElement("inertial");
    if (ci && ci->FirstChildElement("mass"))
      note("link " + cname + " (thruster " + joint + "): its mass " +
           std::to_string(child_number(ci, "mass", jpath, 0.0)) +
           " kg and inertia are not carried (kelp's thrusters are massless)");
    for (const char* e : {"velocity_control", "p_gain", "i_gain", "d_gain"})
      if (p->FirstChildElement(e)) {
        note("Thruster " + joint + ": the propeller joint's control (<" + e +
             ">) and the propeller's reaction torque are not carried");
        break;
      }
    for (const char* e : {"deadband", "power_load", "battery_name", "wake_fraction", "alpha_2"})
      if (p->FirstChildElement(e))
        note("Thruster " + joint + ": <" + std::string(e) + "> is not carried");
  }

  void thrusters_done() {
    if (thrusters_.empty()) return;
    if (thrusters_.size() > std::size_t(vehicle::max_thrusters))
      fail(mpath_, "kelp carries at most " + std::to_string(vehicle::max_thrusters) +
                       " thrusters, the file has " + std::to_string(thrusters_.size()));
    VehicleDescription& d = out_.vehicle;
    vehicle::PropulsionParameters<double> prop;
    const Eigen::Index n = Eigen::Index(thrusters_.size());
    prop.positions.resize(3, n);
    prop.directions.resize(3, n);
    prop.facing = vehicle::ThrusterVector<int>::Ones(n);
    prop.time_constant = 0.0;  // Gazebo's thrust follows its command at once
    for (Eigen::Index i = 0; i < n; ++i) {
      prop.positions.col(i) = thrusters_[std::size_t(i)].position;
      prop.directions.col(i) = thrusters_[std::size_t(i)].direction;
      prop.curves[std::size_t(i)] = thrusters_[std::size_t(i)].curve;
    }
    prop.esc_scale_forward = (d.pwm.max_us - d.pwm.neutral_us) / vehicle::t200_esc_half_range_us;
    prop.esc_scale_reverse = (d.pwm.neutral_us - d.pwm.min_us) / vehicle::t200_esc_half_range_us;
    d.propulsion = prop;
  }

  // The body link's collision volumes: buoyancy (∇, CB) and the hull box.
  void collisions() {
    double volume = 0.0;
    Eigen::Vector3d moment = Eigen::Vector3d::Zero();
    Eigen::Vector3d lo = Eigen::Vector3d::Constant(1e300), hi = -lo;
    for (const XMLElement* c = body_->FirstChildElement("collision"); c;
         c = c->NextSiblingElement("collision")) {
      const std::string path = bpath_ + "/collision[" + name_of(c) + "]";
      const char* rel = relative_to(c);
      if (rel && std::string(rel) != body_name_)
        fail(path + "/pose", "only a collision pose relative to its link is supported");
      const Pose X = pose(c, path);
      const XMLElement* g = c->FirstChildElement("geometry");
      if (g == nullptr) fail(path + "/geometry", "missing");
      double v = 0.0;
      Eigen::Vector3d half;
      if (const XMLElement* b = g->FirstChildElement("box")) {
        const std::vector<double> s =
            numbers(b->FirstChildElement("size") ? b->FirstChildElement("size")->GetText() : "",
                    path + "/geometry/box/size", 3);
        half = 0.5 * Eigen::Vector3d(s[0], s[1], s[2]);
        v = s[0] * s[1] * s[2];
      } else if (const XMLElement* cy = g->FirstChildElement("cylinder")) {
        const double r = child_number(cy, "radius", path + "/geometry/cylinder", -1.0);
        const double l = child_number(cy, "length", path + "/geometry/cylinder", -1.0);
        half = Eigen::Vector3d(r, r, 0.5 * l);
        v = M_PI * r * r * l;
      } else if (const XMLElement* s = g->FirstChildElement("sphere")) {
        const double r = child_number(s, "radius", path + "/geometry/sphere", -1.0);
        half = Eigen::Vector3d::Constant(r);
        v = 4.0 / 3.0 * M_PI * r * r * r;
      } else {
        const XMLElement* any = g->FirstChildElement();
        note("collision " + name_of(c) + " (<" + (any ? any->Name() : "empty") +
             ">): kelp computes volumes of boxes, cylinders and spheres only; not in the "
             "buoyancy");
        continue;
      }
      if (!(v > 0) || !(half.array() > 0).all())
        fail(path + "/geometry", "expected positive dimensions");
      volume += v;
      moment += v * X.t;
      const Eigen::Vector3d ext = X.R.cwiseAbs() * half;  // the rotated box's bounding box
      lo = lo.cwiseMin(X.t - ext);
      hi = hi.cwiseMax(X.t + ext);
    }
    vehicle::VehicleParameters<double>& v = out_.vehicle.parameters;
    if (volume > 0) {
      v.displaced_volume = volume;
      v.r_b = kS * (moment / volume);
      system::HullContact<double> h;
      h.center = kS * (0.5 * (lo + hi));
      h.half_extents = 0.5 * (hi - lo);
      out_.vehicle.hull = h;
    } else {
      v.r_b = v.r_g;
      note("the body link has no box, cylinder or sphere collision: no buoyancy and no hull");
    }
    v.hydrostatics = o_.hydrostatics;
    if (o_.hydrostatics == vehicle::Hydrostatics::surface)
      throw invalid_argument(
          "SdfImportOptions::hydrostatics: the surface model needs a waterplane area and "
          "metacentric heights an SDF does not carry: write them into a vehicle file");
    if (o_.hydrostatics == vehicle::Hydrostatics::submerged_free_surface) {
      if (!(volume > 0))
        fail(bpath_, "submerged_free_surface needs a collision volume (the hull height)");
      v.hull_height = hi(2) - lo(2);
    }
  }

  void other_link(const XMLElement* l) {
    const XMLElement* in = l->FirstChildElement("inertial");
    note("link " + name_of(l) + " is not carried" +
         (in && in->FirstChildElement("mass")
              ? " (mass " + std::to_string(child_number(in, "mass", mpath_, 0.0)) + " kg)"
              : std::string()) +
         ": kelp's vehicle is one rigid body, the model's first link (or SdfImportOptions::link)");
  }

  struct Thruster {
    Eigen::Vector3d position, direction;
    vehicle::ThrustCurve curve;
  };

  std::string file_;
  SdfImportOptions o_;
  SdfImport out_;
  const XMLElement* model_ = nullptr;
  const XMLElement* body_ = nullptr;
  std::string body_name_, mpath_, bpath_;
  std::map<std::string, const XMLElement*> links_, joints_;
  std::set<std::string> thruster_links_, thruster_joints_;
  std::vector<Thruster> thrusters_;
  Pose X_mb_;
  double water_density_ = 0.0, buoyancy_density_ = 0.0;
};

}  // namespace

SdfImport parse_sdf(const std::string& text, const std::string& file,
                    const SdfImportOptions& options) {
  SdfImport out = SdfReader(file, options).read(text);
  detail::check_vehicle(out.vehicle, file);  // the library's checks, naming the file
  return out;
}

SdfImport import_sdf(const std::string& path, const SdfImportOptions& options) {
  std::ifstream in(path);
  if (!in) throw scenario_error(path + ": cannot be read");
  const std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  return parse_sdf(text, path, options);
}

}  // namespace sim
}  // namespace kelp
