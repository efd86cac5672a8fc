"""airtwin: the air-jet manipulation twin from Python (docs/python.md).

Units: SI (m, s, m/s) everywhere; angles people type are in degrees and their names end in
_deg. Arrays of points are N x 2 float64 (x, y in metres, world frame).
"""

from ._core import (  # noqa: F401  (the public API)
    CemPlanner,
    CfdField,
    Field,
    IdentifiedModel,
    PlanResult,
    Prediction,
    Region,
    RunResult,
    Scenario,
    Twin,
    aim,
    identify_series,
    identify_trajectories,
    manipulation_region,
    object_dynamics,
    predict,
    probe_air,
    run_scenario,
    stagnation_point,
)
