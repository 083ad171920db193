#include "model_json.h"

#include <stdexcept>

#include "stewart/model/dc_motor.h"
#include "stewart/model/dynamics.h"
#include "stewart/model/kinematics.h"

namespace stewart {
namespace {

Vector6d Vec6Field(const nlohmann::json& in, const char* key, const Vector6d& fallback) {
  if (!in.contains(key)) return fallback;
  const nlohmann::json& v = in.at(key);
  if (!v.is_array() || v.size() != 6) {
    throw std::invalid_argument(std::string("'") + key + "' must be an array of 6 numbers");
  }
  Vector6d out;
  for (int i = 0; i < 6; ++i) {
    const nlohmann::json& e = v.at(static_cast<size_t>(i));
    if (!e.is_number()) {
      throw std::invalid_argument(std::string("'") + key + "' must be an array of 6 numbers");
    }
    out(i) = e.get<double>();
  }
  if (!out.allFinite()) throw std::invalid_argument(std::string("'") + key + "' must be finite");
  return out;
}

nlohmann::json ToJson(const Vector6d& v) { return std::vector<double>(v.data(), v.data() + 6); }

nlohmann::json ToJson(const Matrix6d& m) {
  nlohmann::json rows = nlohmann::json::array();
  for (int r = 0; r < 6; ++r) rows.push_back(ToJson(Vector6d(m.row(r).transpose())));
  return rows;
}

}  // namespace

ModelQuery ParseModelQuery(const nlohmann::json& in, const Vector6d& default_q) {
  if (!in.is_object()) throw std::invalid_argument("each line must be a JSON object");
  ModelQuery query;
  query.q = Vec6Field(in, "q", default_q);
  query.qd = Vec6Field(in, "qd", Vector6d::Zero());
  query.force_n = Vec6Field(in, "F", Vector6d::Zero());
  query.qdd = Vec6Field(in, "qdd", Vector6d::Zero());
  if (in.contains("l")) {
    query.has_leg_lengths = true;
    query.leg_length_m = Vec6Field(in, "l", Vector6d::Zero());
  }
  return query;
}

nlohmann::json EvaluateModelQuery(const PlatformParams& params, const ModelQuery& query,
                                  const ActuatorConfig* actuators) {
  nlohmann::json out;
  out["q"] = ToJson(query.q);
  out["qd"] = ToJson(query.qd);
  const DynamicsTerms terms = EvaluateDynamics(params, query.q, query.qd);
  out["leg_length_m"] = ToJson(terms.leg_length_m);
  out["in_stroke"] = LegLengthsWithinStroke(params, terms.leg_length_m);
  out["in_workspace"] = PoseInWorkspace(params, query.q);
  const LegGeometry legs = ComputeLegGeometry(params, query.q);
  nlohmann::json base = nlohmann::json::array(), top = nlohmann::json::array();
  for (int i = 0; i < kNumLegs; ++i) {
    const Vector3d b = params.base_joints_in_B_m.col(i);
    const Vector3d a = query.q.head<3>() + legs.platform_offset_in_B_m.col(i);
    base.push_back({b.x(), b.y(), b.z()});
    top.push_back({a.x(), a.y(), a.z()});
  }
  out["base_joints_m"] = base;     // b_i in {B}
  out["platform_joints_m"] = top;  // a_i = t + R p_i in {B}
  out["J_l"] = ToJson(Matrix6d(terms.H.transpose()));
  out["M"] = ToJson(terms.M);
  out["C_qd"] = ToJson(terms.C_qd);
  out["G"] = ToJson(terms.G);
  out["H"] = ToJson(terms.H);
  out["F"] = ToJson(query.force_n);
  out["forward_dynamics_qdd"] = ToJson(ForwardDynamics(terms, query.force_n));
  out["qdd"] = ToJson(query.qdd);
  out["inverse_dynamics_F"] = ToJson(InverseDynamics(terms, query.qdd));
  out["kinetic_energy_j"] = KineticEnergy(terms, query.qd);
  out["potential_energy_j"] = PotentialEnergy(params, query.q);
  if (actuators != nullptr) {
    const Vector6d leg_speed_mps = terms.H.transpose() * query.qd;
    const Vector6d command_n =
        InverseDynamics(terms, query.qdd) + ModelLegDampingNspm(*actuators) * leg_speed_mps;
    nlohmann::json legs_out;
    legs_out["leg_speed_mps"] = ToJson(leg_speed_mps);
    legs_out["command_force_n"] = ToJson(command_n);
    legs_out["force_limit_share"] = command_n.cwiseAbs().maxCoeff() / actuators->force_limit_n;
    if (actuators->kind == ActuatorKind::kDcMotor) {
      legs_out["duty"] = ToJson(DcMotorDutyForDriveForce(actuators->motor, command_n));
    }
    out["actuators"] = legs_out;
  }
  if (query.has_leg_lengths) {
    const ForwardKinematicsResult fk = ForwardKinematics(params, query.leg_length_m, query.q);
    out["forward_kinematics"] = {{"q", ToJson(fk.q)},
                                 {"converged", fk.converged},
                                 {"iterations", fk.iterations},
                                 {"residual_m", fk.residual_m}};
  }
  return out;
}

}  // namespace stewart
