#!/usr/bin/python3
"""The jet's start-up and stop: transient axisymmetric RANS of the rig's jet switched on over a still
floor, then switched off again (docs/cfd.md, "The jet's start-up" and "The jet's stop"). They
measure what the steady campaign cannot: how long the free jet takes to reach the floor, how fast
the wall jet's front runs out along it, when the floor field is steady (the paper's Appendix B:
"approximately 8 seconds"), and how fast the floor's air dies once the jet stops feeding it.

Subcommands (used by startup.sh):
  write   DIR          the start-up case: wedge blockMesh, 0/ fields, PIMPLE dictionaries, probes
  write-stop SRC DIR   the stop case from the start-up's final fields in SRC (their inlet closing
                       over VALVE_S at END_TIME); its first time directory must be made ascii first
  write-pulse DIR MS   a pulse: the start-up's case with the inlet open for MS milliseconds only
                       (what a point beside a sweeping jet receives), run PULSE_AFTER s past it
  progress DIR         one line: simulated time, time step, wall clock per simulated second
  convert DIR OUTDIR   probes -> OUTDIR/<case>.json and _floor.csv, _axis.csv (either case)
  summary DATADIR      the figures of docs/cfd.md from the converted files (and the steady case
                       tilt00.0_mesh1_d20 beside them): transit, wall-jet front, settling, decay
Debian's /usr/bin/python3 with numpy only.
"""
import json
import math
import os
import re
import shutil
import subprocess
import sys

import numpy as np

from cfdcase import (CMU, EPS_AMB, H, INTENSITY, K_AMB, K_KIN, LSCALE, NU, git_commit_of, grading,
                     write_fields, write_file)
from cfdcase import SCHEMES as SCHEMES_STEADY

NAME = "startup_tilt00_d40"
NAME_STOP = "stop_tilt00_d40"
D = 0.040                 # inlet diameter (m): the same momentum flux as the rig's nozzle, see below
WEDGE_DEG = 5.0           # the axisymmetric wedge's opening
WEDGE = "    \"(front|back)\"\n    {\n        type wedge;\n    }\n"  # the fields' wedge patches
R_MAX = 2.0               # domain radius (m)
Z_TOP = 2.0               # domain top (m)
H_CORE = 0.004            # cell size across the inlet and at the exit (m): D / 10
END_TIME = 10.0           # simulated seconds; the paper's CFD was steady at ~8 s
STOP_SPAN = 3.0           # simulated seconds after the valve closes in the stop case
PULSE_AFTER = 1.5         # simulated seconds after a pulse's valve closes
MAX_CO = 2.0              # Courant number the adaptive time step keeps to
VALVE_S = 0.02            # the inlet speed ramps from 0 to its value over this time (a valve opening)
PROBE_DT = 0.02           # probe sampling interval (s)
FIELD_DT = 0.5            # full fields written this often (restart points)
FLOOR_R = np.round(np.arange(0.01, 1.50, 0.02), 4)
FLOOR_Z = [0.004, 0.015, 0.025]
AXIS_Z = np.round(np.arange(0.05, 1.401, 0.05), 4)
AXIS_R = 0.001            # probes 1 mm off the axis (a wedge's axis itself samples badly)


def inlet_state():
    """Inlet speed, k and epsilon for the momentum flux of the real nozzle through diameter D."""
    u = math.sqrt(4.0 * K_KIN / math.pi) / D
    k = 1.5 * (INTENSITY * u) ** 2
    eps = CMU ** 0.75 * k ** 1.5 / (LSCALE * D)
    return u, k, eps


def wedge_point(r, z, side):
    a = math.radians(0.5 * WEDGE_DEG)
    return (r * math.cos(a), side * r * math.sin(a), z)


def block_mesh():
    """Three blocks in (r, z): A under the exit (0..D/2, floor..exit), B beside it (D/2..R_MAX,
    floor..exit) and C beside the rod (D/2..R_MAX, exit..top). A's axis edge is collapsed."""
    r1 = 0.5 * D
    pts, index = [], {}

    def vid(r, z, side):
        key = (r, z, 0 if r == 0.0 else side)
        if key not in index:
            index[key] = len(pts)
            pts.append(wedge_point(r, z, side))
        return index[key]

    def hexa(ra, rb, za, zb):
        return [vid(ra, za, -1), vid(rb, za, -1), vid(rb, za, 1), vid(ra, za, 1),
                vid(ra, zb, -1), vid(rb, zb, -1), vid(rb, zb, 1), vid(ra, zb, 1)]

    A = hexa(0.0, r1, 0.0, H)
    B = hexa(r1, R_MAX, 0.0, H)
    C = hexa(r1, R_MAX, H, Z_TOP)
    n_core = int(round(r1 / H_CORE))
    n_r, g_r = grading([(0.15 - r1, H_CORE, 0.01), (1.05, 0.01, 0.02), (R_MAX - 1.2, 0.02, 0.08)])
    n_z, g_z = grading([(0.15, 0.004, 0.015), (H - 0.15 - 0.13, 0.015, 0.02), (0.13, 0.02, H_CORE)])
    n_t, g_t = grading([(Z_TOP - H, H_CORE, 0.06)])

    def face(b, which):
        local = {"bottom": (0, 3, 2, 1), "top": (4, 5, 6, 7), "rmin": (0, 4, 7, 3), "rmax": (1, 2, 6, 5),
                 "front": (0, 1, 5, 4), "back": (3, 7, 6, 2)}[which]
        return "(%s)" % " ".join(str(b[i]) for i in local)

    def patch(name, kind, faces):
        return "    %s\n    {\n        type %s;\n        faces\n        (\n%s        );\n    }\n" % (
            name, kind, "".join("            %s\n" % f for f in faces))

    body = "scale 1;\n\nvertices\n(\n" + "".join("    (%.9g %.9g %.9g)\n" % p for p in pts) + ");\n\n"
    body += "blocks\n(\n"
    body += "    hex (%s) (%d 1 %d) simpleGrading (1 1 %s)\n" % (" ".join(map(str, A)), n_core, n_z, g_z)
    body += "    hex (%s) (%d 1 %d) simpleGrading (%s 1 %s)\n" % (" ".join(map(str, B)), n_r, n_z, g_r, g_z)
    body += "    hex (%s) (%d 1 %d) simpleGrading (%s 1 %s)\n" % (" ".join(map(str, C)), n_r, n_t, g_r, g_t)
    body += ");\n\nedges\n(\n);\n\nboundary\n(\n"
    body += patch("inlet", "patch", [face(A, "top")])
    body += patch("rod_wall", "wall", [face(C, "rmin")])
    body += patch("floor", "wall", [face(A, "bottom"), face(B, "bottom")])
    body += patch("atmosphere", "patch", [face(B, "rmax"), face(C, "rmax"), face(C, "top")])
    body += patch("front", "wedge", [face(b, "front") for b in (A, B, C)])
    body += patch("back", "wedge", [face(b, "back") for b in (A, B, C)])
    body += ");\n\nmergePatchPairs\n(\n);\n"
    cells = n_core * n_z + n_r * n_z + n_r * n_t
    return body, cells


CONTROL = """application     pimpleFoam;
startFrom       latestTime;
startTime       0;
stopAt          endTime;
endTime         %(end)g;
deltaT          1e-5;
adjustTimeStep  yes;
maxCo           %(co)g;
maxDeltaT       0.01;
writeControl    adjustableRunTime;
writeInterval   %(field_dt)g;
purgeWrite      2;
writeFormat     binary;
writePrecision  8;
writeCompression off;
timeFormat      general;
timePrecision   8;
runTimeModifiable false;

functions
{
%(probes)s}
"""

# The steady cases' schemes, time-accurate: Euler in time, and without the steady solver's
# "bounded" convection (which subtracts the continuity error a converged steady state drives to 0).
SCHEMES = SCHEMES_STEADY.replace("default steadyState;", "default Euler;").replace(
    "bounded Gauss", "Gauss")

SOLUTION = """solvers
{
    p
    {
        solver          GAMG;
        smoother        GaussSeidel;
        tolerance       1e-6;
        relTol          0.01;
    }
    pFinal
    {
        $p;
        relTol          0;
    }
    "(U|k|epsilon)"
    {
        solver          smoothSolver;
        smoother        symGaussSeidel;
        tolerance       1e-7;
        relTol          0.1;
    }
    "(U|k|epsilon)Final"
    {
        $U;
        relTol          0;
    }
}

PIMPLE
{
    momentumPredictor yes;
    nOuterCorrectors 1;
    nCorrectors     2;
    nNonOrthogonalCorrectors 0;
}

relaxationFactors
{
    equations { ".*" 1; }
}
"""


def probes_entry(name, fields, pts):
    s = "    %s\n    {\n        type probes;\n        libs (\"libsampling.so\");\n" % name
    s += "        executeControl adjustableRunTime;\n        executeInterval %g;\n" % PROBE_DT
    s += "        writeControl adjustableRunTime;\n        writeInterval %g;\n" % PROBE_DT
    s += "        fields (%s);\n        probeLocations\n        (\n" % " ".join(fields)
    s += "".join("            (%.6f 0 %.6f)\n" % p for p in pts)
    return s + "        );\n    }\n"


def floor_points():
    return [(r, z) for z in FLOOR_Z for r in FLOOR_R]


def axis_points():
    return [(AXIS_R, z) for z in AXIS_Z]


def ramp(value_at, pulse_s=None):
    """uniformFixedValue table over the valve's opening: value_at(f) at t = f VALVE_S, f = 0..1;
    with pulse_s, closing again over VALVE_S from t = pulse_s."""
    n = 10
    rows = ["(%.6g %s)" % (VALVE_S * i / n, value_at(i / n)) for i in range(n + 1)]
    if pulse_s is not None:
        rows += ["(%.6g %s)" % (pulse_s + VALVE_S * i / n, value_at(1.0 - i / n)) for i in range(n + 1)]
    return " ".join(rows)


def pulse_name(pulse_s):
    return "pulse%03dms_tilt00_d40" % round(1000 * pulse_s)


def cmd_write(case_dir, pulse_s=None):
    """The start-up case, or with pulse_s a pulse: the inlet open from 0 to pulse_s only."""
    if pulse_s is not None and not VALVE_S < pulse_s <= 2.0:
        sys.exit("startup: pulse length %g s: expected (%g, 2] s" % (pulse_s, VALVE_S))
    # a pulse ends on a probe time, so its last probe is at the end (the probes write every PROBE_DT)
    end = END_TIME if pulse_s is None else PROBE_DT * math.ceil((pulse_s + VALVE_S + PULSE_AFTER) / PROBE_DT - 1e-9)
    name = NAME if pulse_s is None else pulse_name(pulse_s)
    bm, cells = block_mesh()
    write_file(os.path.join(case_dir, "system/blockMeshDict"), "dictionary", "blockMeshDict", bm)
    probes = probes_entry("floor", ["U", "k", "epsilon"], floor_points())
    probes += probes_entry("axis", ["U"], axis_points())
    write_file(os.path.join(case_dir, "system/controlDict"), "dictionary", "controlDict",
               CONTROL % {"end": end, "co": MAX_CO, "field_dt": FIELD_DT, "probes": probes})
    write_file(os.path.join(case_dir, "system/fvSchemes"), "dictionary", "fvSchemes", SCHEMES)
    write_file(os.path.join(case_dir, "system/fvSolution"), "dictionary", "fvSolution", SOLUTION)
    write_file(os.path.join(case_dir, "constant/transportProperties"), "dictionary",
               "transportProperties", "transportModel Newtonian;\nnu [0 2 -1 0 0 0 0] %g;\n" % NU)
    write_file(os.path.join(case_dir, "constant/turbulenceProperties"), "dictionary",
               "turbulenceProperties",
               "simulationType RAS;\nRAS\n{\n    RASModel kEpsilon;\n    turbulence on;\n"
               "    printCoeffs on;\n}\n")
    u, k_in, eps_in = inlet_state()
    # the inlet's k and epsilon follow its speed (as U^2, U^3) from the ambient values up
    write_fields(os.path.join(case_dir, "0"), "inlet", WEDGE,
                 ramp(lambda f: "(0 0 %.9g)" % (-f * u), pulse_s), "(0 0 0)",
                 ramp(lambda f: "%.9g" % max(K_AMB, k_in * f ** 2), pulse_s), "%g" % K_AMB,
                 ramp(lambda f: "%.9g" % max(EPS_AMB, eps_in * f ** 3), pulse_s), "%g" % EPS_AMB)
    gen = ("scripts/cfd/startup.py", "scripts/cfd/startup.sh")
    meta = {"case": name, "kind": "start" if pulse_s is None else "pulse", "generator_commit": git_commit_of(os.path.dirname(os.path.abspath(__file__)), gen),
            "cells": cells, "inlet_d_m": D, "inlet_speed_m_s": u, "k_inlet": k_in, "epsilon_inlet": eps_in,
            "momentum_flux_kinematic_m4_s2": K_KIN, "wedge_deg": WEDGE_DEG, "end_time_s": end,
            "max_courant": MAX_CO, "valve_opening_s": VALVE_S}
    if pulse_s is not None:
        meta["pulse_s"] = pulse_s
    with open(os.path.join(case_dir, "case.json"), "w") as fh:
        json.dump(meta, fh, indent=1)
    print("%s: %d cells, inlet %.1f m/s" % (name, cells, u))


def close_table(text, value_at, end):
    """Replaces the inlet's uniformValue table in an ascii field file by the valve's closing: the
    full value until END_TIME, value_at(1 - f) at END_TIME + f VALVE_S, f = 0..1."""
    n = 10
    rows = ["(0 %s)" % value_at(1.0)] + ["(%.6g %s)" % (end + VALVE_S * i / n, value_at(1.0 - i / n))
                                        for i in range(n + 1)]
    pat = re.compile(r"(inlet\s*\{[^}]*?uniformValue\s+table)\s*\d*\s*\((?:[^;]*)\);", re.S)
    new, count = pat.subn(lambda m: "%s (%s);" % (m.group(1), " ".join(rows)), text, count=1)
    if count != 1:
        sys.exit("startup: no inlet uniformValue table to close in a field file")
    return new


def cmd_write_stop(src_dir, case_dir):
    """The stop case: the start-up's fields at END_TIME, the inlet closing like a valve over
    VALVE_S from then on (speed to 0, its k and epsilon back to the ambient's), run STOP_SPAN on."""
    start = os.path.join(src_dir, "%g" % END_TIME)
    if not os.path.isdir(start):
        sys.exit("startup: %s: no fields at t = %g s (run the start-up case to its end first)" %
                 (src_dir, END_TIME))
    os.makedirs(case_dir, exist_ok=True)
    for sub in ("constant", "system"):
        shutil.copytree(os.path.join(src_dir, sub), os.path.join(case_dir, sub), dirs_exist_ok=True)
    shutil.copytree(start, os.path.join(case_dir, "%g" % END_TIME), dirs_exist_ok=True)
    probes = probes_entry("floor", ["U", "k", "epsilon"], floor_points())
    probes += probes_entry("axis", ["U"], axis_points())
    control = CONTROL % {"end": END_TIME + STOP_SPAN, "co": MAX_CO, "field_dt": FIELD_DT, "probes": probes}
    # the start-up wrote binary fields; make the first one ascii to edit its inlet's tables
    write_file(os.path.join(case_dir, "system/controlDict"), "dictionary", "controlDict",
               control.replace("writeFormat     binary;", "writeFormat     ascii;"))
    conv = subprocess.run(["nice", "-n", "19", "foamFormatConvert", "-time", "%g" % END_TIME],
                          cwd=case_dir, capture_output=True, text=True)
    if conv.returncode != 0:
        sys.exit("startup: foamFormatConvert failed in %s: %s" % (case_dir, conv.stderr.strip()[-300:]))
    write_file(os.path.join(case_dir, "system/controlDict"), "dictionary", "controlDict", control)
    u, k_in, eps_in = inlet_state()
    edits = (("U", lambda f: "(0 0 %.9g)" % (-f * u)),
             ("k", lambda f: "%.9g" % max(K_AMB, k_in * f ** 2)),
             ("epsilon", lambda f: "%.9g" % max(EPS_AMB, eps_in * f ** 3)))
    for fld, value_at in edits:
        path = os.path.join(case_dir, "%g" % END_TIME, fld)
        text = open(path).read()
        with open(path, "w") as fh:
            fh.write(close_table(text, value_at, END_TIME))
    gen = ("scripts/cfd/startup.py", "scripts/cfd/startup.sh")
    meta = json.load(open(os.path.join(src_dir, "case.json")))
    meta.update({"case": NAME_STOP, "kind": "stop", "started_from": NAME,
                 "generator_commit": git_commit_of(os.path.dirname(os.path.abspath(__file__)), gen),
                 "stop_time_s": END_TIME, "end_time_s": END_TIME + STOP_SPAN,
                 "valve_closing_s": VALVE_S})
    meta.pop("valve_opening_s", None)
    with open(os.path.join(case_dir, "case.json"), "w") as fh:
        json.dump(meta, fh, indent=1)
    print("%s: from %s at %g s, the inlet closing over %g s, to %g s" %
          (NAME_STOP, NAME, END_TIME, VALVE_S, END_TIME + STOP_SPAN))


TIME_RE = re.compile(r"^Time = ([0-9.eE+-]+)", re.M)
DT_RE = re.compile(r"^deltaT = ([0-9.eE+-]+)", re.M)
CLOCK_RE = re.compile(r"ExecutionTime = ([0-9.]+) s", re.M)


def cmd_progress(case_dir):
    txt = ""
    for fn in sorted(os.listdir(case_dir)):
        if fn.startswith("log.pimpleFoam"):
            txt = open(os.path.join(case_dir, fn), errors="replace").read()
    times = [float(v) for v in TIME_RE.findall(txt)]
    dts = DT_RE.findall(txt)
    clocks = [float(v) for v in CLOCK_RE.findall(txt)]
    if not times:
        print("not started")
        return
    end = json.load(open(os.path.join(case_dir, "case.json"))).get("end_time_s", END_TIME)
    parts = ["t %.3f s of %g" % (times[-1], end)]
    if dts:
        parts.append("dt %.2e s" % float(dts[-1]))
    if len(times) > 200 and len(clocks) > 200:
        span = times[-1] - times[-201]
        if span > 0:
            parts.append("%.0f s wall per simulated s" % ((clocks[-1] - clocks[-201]) / span))
    print(", ".join(parts))


# ---------------------------------------------------------------- conversion
def read_probe_series(pp_dir, field, n, running=False):
    """Every restart's file of one probed field, merged by time (a restart repeats nothing kept).
    running: the solver is still writing, so a line of the wrong length (the one being written)
    is left out instead of being an error."""
    rows = {}
    if not os.path.isdir(pp_dir):
        sys.exit("startup: no probes in %s" % pp_dir)
    for start in sorted(os.listdir(pp_dir), key=float):
        path = os.path.join(pp_dir, start, field)
        if not os.path.exists(path):
            continue
        for line in open(path):
            if line.startswith("#") or not line.strip():
                continue
            vals = line.replace("(", " ").replace(")", " ").split()
            t = round(float(vals[0]), 6)
            data = np.array(vals[1:], dtype=float)
            if running and rows and data.size != next(iter(rows.values())).size:
                continue
            if data.size % n:
                if running:
                    continue
                sys.exit("startup: %s: %d values at t %g, expected a multiple of %d probes" %
                         (path, data.size, t, n))
            rows[t] = data.reshape(n, -1)
    if not rows:
        sys.exit("startup: no %s samples in %s" % (field, pp_dir))
    times = np.array(sorted(rows))
    return times, np.stack([rows[t] for t in times])


def first_crossing(t, y, level):
    """First time y reaches level, linear between samples; None if it never does."""
    above = np.nonzero(y >= level)[0]
    if above.size == 0:
        return None
    i = above[0]
    if i == 0:
        return float(t[0])
    return float(t[i - 1] + (level - y[i - 1]) / (y[i] - y[i - 1]) * (t[i] - t[i - 1]))


def settle_time(t, y, final, tol):
    """Last time |y - final| exceeds tol * |final| (the field is within tol from then on)."""
    out = np.nonzero(np.abs(y - final) > tol * abs(final))[0]
    return float(t[out[-1] + 1]) if out.size and out[-1] + 1 < t.size else (float(t[0]) if not out.size
                                                                              else None)


def decay_figures(t, y, stop):
    """From the value when the valve starts closing: the times after it at which y falls to half
    and to a tenth of it (None if it never does within the run)."""
    initial = float(y[np.argmin(np.abs(t - stop))])
    fall = np.sign(initial) * y
    after = t >= stop - 1e-9
    entry = {"initial_m_s": initial}
    for key, frac in (("half_s", 0.5), ("tenth_s", 0.1)):
        c = first_crossing(t[after], -fall[after], -frac * abs(initial))
        entry[key] = None if c is None else c - stop
    return entry


def cmd_convert(case_dir, out_dir):
    meta = json.load(open(os.path.join(case_dir, "case.json")))
    name = meta["case"]
    kind = meta.get("kind", "start")
    stop = meta["stop_time_s"] if kind == "stop" else None
    end = meta.get("end_time_s", END_TIME)
    fl = floor_points()
    t, U = read_probe_series(os.path.join(case_dir, "postProcessing/floor"), "U", len(fl))
    tk, K = read_probe_series(os.path.join(case_dir, "postProcessing/floor"), "k", len(fl))
    ta, UA = read_probe_series(os.path.join(case_dir, "postProcessing/axis"), "U", len(axis_points()))
    if t.size != tk.size:
        sys.exit("startup: U and k probes disagree in their times")
    # the probes write every PROBE_DT: the last is the last multiple of it at or before the end
    if t[-1] < PROBE_DT * math.floor(end / PROBE_DT + 1e-9) - 1e-6:
        sys.exit("startup: the run reached %g s of %g; finish it before converting" % (t[-1], end))
    ur = U[:, :, 0]                     # radial (the wedge's centre plane is y = 0)
    nr = len(FLOOR_R)
    uz = -UA[:, :, 2]
    figures = {"floor": [], "axis": []}
    if kind == "pulse":
        # the peak each probe reaches, against the start-up's steady value there
        steady_path = os.path.join(out_dir, NAME + ".json")
        if not os.path.exists(steady_path):
            sys.exit("startup: %s: the start-up's figures are needed to convert a pulse" % steady_path)
        steady = {(e["height_m"], round(e["r_m"], 4)): e["final_ur_m_s"]
                  for e in json.load(open(steady_path))["figures"]["floor"]}
        for hi, z in enumerate(FLOOR_Z):
            for ri, r in enumerate(FLOOR_R):
                y = ur[:, hi * nr + ri]
                final = steady[(z, round(float(r), 4))]
                i = int(np.argmax(np.sign(final) * y))
                figures["floor"].append({"height_m": z, "r_m": float(r), "steady_ur_m_s": final,
                                         "peak_ur_m_s": float(y[i]), "peak_t_s": float(t[i]),
                                         "peak_fraction": float(y[i] / final) if abs(final) >= 0.3
                                         else None})
    elif stop is None:
        # the last second's mean is the steady state the start-up tends to
        last = t >= end - 1.0
        for hi, z in enumerate(FLOOR_Z):
            for ri, r in enumerate(FLOOR_R):
                y = ur[:, hi * nr + ri]
                final = float(y[last].mean())
                entry = {"height_m": z, "r_m": float(r), "final_ur_m_s": final,
                         "final_std_m_s": float(y[last].std())}
                if abs(final) >= 0.3:
                    entry["arrival_s"] = first_crossing(t, np.sign(final) * y, 0.5 * abs(final))
                    entry["within_5pct_s"] = settle_time(t, y, final, 0.05)
                    entry["within_10pct_s"] = settle_time(t, y, final, 0.10)
                figures["floor"].append(entry)
        for zi, z in enumerate(AXIS_Z):
            final = float(uz[ta >= end - 1.0, zi].mean())
            figures["axis"].append({"z_m": float(z), "final_uz_down_m_s": final,
                                    "arrival_s": first_crossing(ta, uz[:, zi], 0.5 * final)})
    else:
        for hi, z in enumerate(FLOOR_Z):
            for ri, r in enumerate(FLOOR_R):
                entry = {"height_m": z, "r_m": float(r)}
                entry.update(decay_figures(t, ur[:, hi * nr + ri], stop))
                figures["floor"].append(entry)
        for zi, z in enumerate(AXIS_Z):
            entry = {"z_m": float(z)}
            entry.update(decay_figures(ta, uz[:, zi], stop))
            figures["axis"].append(entry)
    os.makedirs(out_dir, exist_ok=True)
    meta["probe_interval_s"] = PROBE_DT
    meta["figures"] = figures
    with open(os.path.join(out_dir, name + ".json"), "w") as fh:
        json.dump(meta, fh, indent=1)
    # the floor's time series at every 0.05 s (2.5x the probe interval: the CSV stays small)
    keep = np.nonzero(np.isclose((t / 0.05) - np.round(t / 0.05), 0.0, atol=1e-6))[0]
    with open(os.path.join(out_dir, name + "_floor.csv"), "w") as fh:
        fh.write("t,height_m,r_m,ur,uz,k\n")
        for i in keep:
            for hi, z in enumerate(FLOOR_Z):
                for ri, r in enumerate(FLOOR_R):
                    j = hi * nr + ri
                    fh.write("%.2f,%.4f,%.3f,%.4f,%.4f,%.4f\n" % (t[i], z, r, U[i, j, 0], U[i, j, 2], K[i, j, 0]))
    keep_a = np.nonzero(np.isclose((ta / 0.05) - np.round(ta / 0.05), 0.0, atol=1e-6))[0]
    with open(os.path.join(out_dir, name + "_axis.csv"), "w") as fh:
        fh.write("t,z_m,uz_down\n")
        for i in keep_a:
            for zi, z in enumerate(AXIS_Z):
                fh.write("%.2f,%.3f,%.4f\n" % (ta[i], z, uz[i, zi]))
    print("%s: %d samples to %.2f s" % (name, t.size, t[-1]))


def cmd_summary(data_dir):
    meta = json.load(open(os.path.join(data_dir, NAME + ".json")))
    fl = [e for e in meta["figures"]["floor"] if e["height_m"] == 0.015]
    ax = meta["figures"]["axis"]
    print("free jet: the head (half its final downward speed) reaches")
    for e in ax:
        if round(e["z_m"] * 100) % 20 == 0 or e["z_m"] <= 0.051:
            print("  z %.2f m (%.2f m from the exit): %s s" %
                  (e["z_m"], H - e["z_m"], "%.3f" % e["arrival_s"] if e["arrival_s"] is not None
                   else "never"))
    rows = [e for e in fl if "arrival_s" in e and e["arrival_s"] is not None]
    print("wall jet at 15 mm: r, final u_r, arrival (half of final), within 10 %, within 5 %")
    for e in rows:
        if round(e["r_m"] * 100) % 10 == 9 or e["r_m"] in (0.19, 0.29):
            print("  %.2f m  %.2f m/s  %.3f s  %s  %s" % (
                e["r_m"], e["final_ur_m_s"], e["arrival_s"],
                "%.2f s" % e["within_10pct_s"] if e["within_10pct_s"] is not None else "-",
                "%.2f s" % e["within_5pct_s"] if e["within_5pct_s"] is not None else "-"))
    fit = [(e["r_m"], e["arrival_s"]) for e in rows if 0.3 <= e["r_m"] <= 1.0]
    if len(fit) >= 3:
        r = np.array([f[0] for f in fit])
        t = np.array([f[1] for f in fit])
        slope, icpt = np.polyfit(r, t, 1)
        print("front: arrival = %.3f s + r / %.2f m/s over r 0.3-1.0 m (RMS %.3f s)" %
              (icpt, 1.0 / slope, float(np.sqrt(np.mean((icpt + slope * r - t) ** 2)))))
    for lim in (1.0, 1.2):
        s10 = [e["within_10pct_s"] for e in rows if e["r_m"] <= lim]
        s5 = [e["within_5pct_s"] for e in rows if e["r_m"] <= lim]
        if s10 and None not in s10 and None not in s5:
            print("steady out to %.1f m: within 10 %% by %.2f s, within 5 %% by %.2f s" %
                  (lim, max(s10), max(s5)))
    steady = os.path.join(data_dir, "tilt00.0_mesh1_d20_walljet.csv")
    if os.path.exists(steady):
        ref = np.genfromtxt(steady, delimiter=",", names=True)
        ref = ref[ref["direction_deg"] == 0.0]
        errs = []
        for e in rows:
            if 0.1 <= e["r_m"] <= 1.2:
                u = np.interp(e["r_m"], ref["r_from_c_m"], ref["u_z015_m_s"])
                errs.append(abs(e["final_ur_m_s"] - u) / u)
        if errs:
            print("final u_r at 15 mm against the steady 3-D case (inlet 20 mm), r 0.1-1.2 m: "
                  "MAPE %.1f %%, worst %.1f %%" % (100 * np.mean(errs), 100 * max(errs)))


def stop_summary(data_dir):
    """The stop case's figures beside the start-up's arrivals (docs/cfd.md, "The jet's stop")."""
    path = os.path.join(data_dir, NAME_STOP + ".json")
    if not os.path.exists(path):
        return
    stop = json.load(open(path))
    start = json.load(open(os.path.join(data_dir, NAME + ".json")))
    arrival = {(e["height_m"], round(e["r_m"], 3)): e.get("arrival_s") for e in start["figures"]["floor"]}
    print("jet stopped at %g s: the floor's radial air at 15 mm after the valve closes" % stop["stop_time_s"])
    print("  r, before, half, tenth (s after the stop) | start-up arrival (half) at the same r")
    for e in stop["figures"]["floor"]:
        if e["height_m"] != 0.015 or round(e["r_m"] * 100) % 10 != 1 or e["r_m"] < 0.1:
            continue
        fmt = lambda v: "%.2f s" % v if v is not None else "beyond the run"
        a = arrival.get((0.015, round(e["r_m"], 3)))
        print("  %.2f m  %.2f m/s  %s  %s | %s" % (e["r_m"], e["initial_m_s"], fmt(e["half_s"]),
                                                 fmt(e["tenth_s"]), fmt(a)))
    low = min(stop["figures"]["axis"], key=lambda e: e["z_m"])
    print("free jet at z %.2f m: half in %.2f s after the stop, a tenth in %.2f s" %
          (low["z_m"], low["half_s"], low["tenth_s"]))


def pulse_summary(data_dir):
    """Each pulse's peak floor air against the steady jet's (docs/cfd.md, "A short pulse")."""
    for fn in sorted(os.listdir(data_dir)):
        if not (fn.startswith("pulse") and fn.endswith(".json")):
            continue
        m = json.load(open(os.path.join(data_dir, fn)))
        print("pulse %s: the jet open %.0f ms; the floor's radial air at 4 mm, its peak and when" %
              (m["case"], 1000 * m["pulse_s"]))
        for e in m["figures"]["floor"]:
            if e["height_m"] != 0.004 or round(e["r_m"] * 100) % 10 != 1 or e["r_m"] < 0.1:
                continue
            frac = e["peak_fraction"]
            print("  %.2f m  steady %.2f m/s  peak %.2f m/s (%s)  at %.2f s" %
                  (e["r_m"], e["steady_ur_m_s"], e["peak_ur_m_s"],
                   "%.0f %%" % (100 * frac) if frac is not None else "-", e["peak_t_s"]))


def main(argv):
    if len(argv) == 3 and argv[1] == "write":
        cmd_write(argv[2])
    elif len(argv) == 4 and argv[1] == "write-stop":
        cmd_write_stop(argv[2], argv[3])
    elif len(argv) == 4 and argv[1] == "write-pulse":
        cmd_write(argv[2], float(argv[3]) / 1000.0)
    elif len(argv) == 3 and argv[1] == "progress":
        cmd_progress(argv[2])
    elif len(argv) == 4 and argv[1] == "convert":
        cmd_convert(argv[2], argv[3])
    elif len(argv) == 3 and argv[1] == "summary":
        cmd_summary(argv[2])
        stop_summary(argv[2])
        pulse_summary(argv[2])
    else:
        sys.exit(__doc__)


if __name__ == "__main__":
    main(sys.argv)
