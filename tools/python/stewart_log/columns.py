"""Column names of the tables: those of stewart_log_export's CSV files
(tools/log_export/csv_writers.cc) for every field the CSV has, in the same
style for the fields it leaves out, so a table and a CSV compare column by
column (tests/python_log checks that they do). A field of a type or of a
version this table does not know is still a column: `name`, or `name_<i>`
per element of an array (row-major for several dimensions).
"""
_AXES = ("x", "y", "z", "phi", "theta", "psi")

# A field whose elements are rather one value: a lower-case hex string column.
HEX = "hex"


def _axis(name, linear_unit, angular_unit):
    return lambda i: f"{name}_{_AXES[i]}_{linear_unit if i < 3 else angular_unit}"


def _indexed(name, unit):
    return lambda i: f"{name}{i}_{unit}"


def _listed(*names):
    return lambda i: names[i]


_COMMON = {"utime": "utime_us", "sample_utime": "sample_utime_us"}

_BY_TYPE = {
    "stewart.sensor_t": {
        "leg_length_m": _indexed("leg_length", "m"),
        "gyro_radps": _listed("gyro_x_radps", "gyro_y_radps", "gyro_z_radps"),
        "accel_mps2": _listed("accel_x_mps2", "accel_y_mps2", "accel_z_mps2"),
        "orientation_rpy_rad": _listed("roll_rad", "pitch_rad", "yaw_rad"),
    },
    "stewart.state_t": {
        "q": _axis("q", "m", "rad"),
        "qd": _axis("qd", "mps", "radps"),
        "q_std": _axis("q_std", "m", "rad"),
        "qd_std": _axis("qd_std", "mps", "radps"),
        "disturbance": _axis("disturbance", "n", "nm"),
        "disturbance_std": _axis("disturbance_std", "n", "nm"),
    },
    "stewart.setpoint_t": {
        "q_des": _axis("q_des", "m", "rad"),
        "qd_des": _axis("qd_des", "mps", "radps"),
        "qdd_des": _axis("qdd_des", "mps2", "radps2"),
    },
    "stewart.force_command_t": {
        "force_n": _indexed("force", "n"),
        "mac": HEX,
    },
    "stewart.safety_diagnostics_t": {
        **{f"{q}_{group}": _indexed(f"{q}_{group}", "")
           for q in ("h", "alpha_h", "w", "mu") for group in ("position", "velocity")},
        "g_p": _indexed("g_p", ""),
        "g_v": _indexed("g_v", ""),
        "mu_force": _indexed("mu_force", ""),
        "f_des": _indexed("f_des", "n"),
        "f_safe": _indexed("f_safe", "n"),
        "f_nominal": _indexed("f_nominal", "n"),
        "correction_norm": "correction_norm_n",
    },
    "stewart.supervisor_state_t": {"mac": HEX},
    "stewart.operator_command_t": {"mac": HEX},
}


def rule(type_name, field_name):
    """How a field becomes columns: a str (the one column's name), HEX, a
    function of the element index, or None (the default names)."""
    return _BY_TYPE.get(type_name, {}).get(field_name, _COMMON.get(field_name))


def column_name(type_name, field, element):
    """The column of one element of a field that rule() does not mark HEX."""
    named = rule(type_name, field.name)
    if isinstance(named, str):
        return named
    if named is not None:
        return named(element)
    return f"{field.name}_{element}" if field.dims else field.name
