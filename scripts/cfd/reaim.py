#!/usr/bin/python3
"""A re-aim of the rig's jet in 3-D (docs/cfd.md, "A re-aim in 3-D"): transient RANS of the jet
held at one tilt until steady, then turned at the servos' speed to another tilt and held there.
It measures what the axisymmetric start-up and pulses cannot: how the new wall jet forms when it
runs into the old one's moving air, at a tilt, which is what the twin's lag and formation
(sim/air_transport.h) model after every re-aim of the Appendix D protocol and the controller.

The jet turns without a moving mesh: the nozzle is a fixed rod on the bisector of the two tilts
and its exit cap blows at the tilt of the moment (the inlet's velocity turns; its speed is set so
the momentum flux through the cap stays the real nozzle's, u^2 A cos(delta) = K / 2 on the half
domain, delta the angle between the velocity and the rod). Two steady cases on the same mesh,
blowing at each end tilt, check that this makes the campaign's steady floor field.

Subcommands (used by reaim.sh):
  list                       the cases: name, from tilt, to tilt, the case whose mesh it shares
  write CASE DIR             the mesh's dictionaries and the rod (the bisector's)
  steady CASE DIR TILT       after meshing: 0/ fields and dictionaries of a steady run blowing at TILT
  transient CASE SRC DIR     the transient from the steady fields in SRC (blowing at the case's
                             first tilt), with its inlet program and floor probes
  progress DIR               one line: simulated time, time step, wall clock per simulated second
  convert CASE DIR OUTDIR FROM TO
                             probes -> OUTDIR/<case>.json and <case>_floor.csv (FROM, TO: the
                             steady ends' directories, whose run records it keeps)
  sample-steady DIR          the probes at the latest time of a finished steady run (postProcess)
  compare CASE DATADIR STEADY_TO AIRTWIN OUTDIR [--png FILE]
                             the CFD's re-aim against the twin's moving air (`airtwin probe`)
                             without and with the formation at several time scales; a JSON report
                             in OUTDIR, a summary on stdout and, with --png, a picture
  carried CASE DATADIR STEADY_TO AIRTWIN OUTDIR
                             the new front's lag carried by the old air's component along its
                             path (co-flow and counter-flow weights), against the CFD's half-way
                             times (needs the Python bindings beside AIRTWIN)
  compare-visit CASE DATADIR CASEDIR STEADY_TO AIRTWIN OUTDIR [--png FILE]
                             a visit against the twin's moving air: the largest share of the
                             visited tilt's air each point gets, by side and distance from its s
                             (from CASEDIR's probes while the run is not converted yet)
STEADY_TO is a finished steady run's directory, or data:CASE: the converted transient CASE in
DATADIR that starts from the steady state at the second tilt on the same mesh (its record before
the turn), e.g. data:reaim_t22.5_t00.0_d40 for the air at 22.5 deg.
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

import cfdcase
from cfdcase import (CMU, H, INTENSITY, K_KIN, LSCALE, Geo, block_mesh,
                     git_commit_of, patch_area, read_boundary, rod_stl, snappy_dict, write_file)
from startup import CONTROL
from startup import SCHEMES as SCHEMES_TRANSIENT
from startup import SOLUTION as SOLUTION_TRANSIENT
from startup import cmd_progress as startup_progress
from startup import read_probe_series

D = 0.040                 # inlet diameter (m), as the start-up's (same momentum flux, docs/cfd.md)
SLEW_RAD_S = 7.0          # the servos' top speed (sim/nozzle_actuator.h)
HOLD_BEFORE_S = 0.1       # the first tilt held this long in the transient before the turn
HOLD_AFTER_S = 1.0        # the second tilt held this long after the turn
VISIT_AFTER_S = 0.7       # a visit's first tilt held this long after the turn back
MAX_CO = 2.0
PROBE_DT = 0.01
CSV_DT = 0.02            # the CSV keeps every other probe time (it stays ~3 MB)
FIELD_DT = 0.1            # full fields written this often (restart points)
STEADY_ITER = 1500        # cap of a steady run (it stops on its residuals first)
PROBE_X = np.round(np.arange(-1.0, 1.6001, 0.04), 4)
PROBE_Y = [0.0005, 0.1, 0.2, 0.3, 0.45, 0.6]
PROBE_Z = [0.004, 0.015]
GEN = ("scripts/cfd/reaim.py", "scripts/cfd/reaim.sh")


def cases():
    """A re-aim turns from one tilt to another and holds it; a visit (visit_s) holds the second
    tilt that long and turns back: a sweep's brief pass over the floor. `mesh` names the case
    whose mesh and steady ends (the same tilts, the same rod) a case shares."""
    reaim = {"name": "reaim_t00.0_t22.5_d40", "from_deg": 0.0, "to_deg": 22.5}
    visit = {"name": "visit_t00.0_t22.5_h0.10_d40", "from_deg": 0.0, "to_deg": 22.5, "visit_s": 0.1}
    # the way back, held 0.8 s (the half-way times 0.1-0.7 m from s come within it)
    back = {"name": "reaim_t22.5_t00.0_d40", "from_deg": 22.5, "to_deg": 0.0, "hold_after_s": 0.8}
    for c in (reaim, visit, back):
        c.setdefault("mesh", reaim["name"])
    return [reaim, visit, back]


def find(name):
    for c in cases():
        if c["name"] == name:
            return c
    sys.exit("reaim: unknown case '%s' (see reaim.sh --list)" % name)


def direction(tilt_deg):
    t = math.radians(tilt_deg)
    return np.array([math.sin(t), 0.0, -math.cos(t)])


def geometry(case):
    """cfdcase's geometry with the rod on the bisector, the floor's fine zone and the jet's
    refinement covering both tilts."""
    mid = 0.5 * (case["from_deg"] + case["to_deg"])
    g = Geo({"tilt_deg": mid, "mesh_level": 1, "inlet_d": D})
    far = max(case["from_deg"], case["to_deg"])
    g.c = H * math.tan(math.radians(far))
    g.x1 = max(2.0, g.c + 2.0)
    return g


def fan_shells(g, case):
    """cfdcase's refinement cylinders along each end tilt and the bisector."""
    out = []
    for tilt in (case["from_deg"], 0.5 * (case["from_deg"] + case["to_deg"]), case["to_deg"]):
        gt = Geo({"tilt_deg": tilt, "mesh_level": 1, "inlet_d": D})
        gt.ls = g.ls
        for lvl, rad, back, ahead in cfdcase.shells(gt):
            # behind the exit the rod's own axis, ahead of it the tilt's
            out.append((lvl, rad, g.p0 - back * g.d, g.p0 + ahead * gt.d))
    return out


def cmd_write(name, case_dir):
    case = find(name)
    g = geometry(case)
    bm, nbg = block_mesh(g)
    write_file(os.path.join(case_dir, "system/blockMeshDict"), "dictionary", "blockMeshDict", bm)
    # cfdcase's snappy dictionary with its cylinders replaced by the fan's
    text = snappy_dict(g)
    geo = "    rod.stl\n    {\n        type triSurfaceMesh;\n        name rod;\n    }\n"
    regions = ""
    for i, (lvl, rad, p1, p2) in enumerate(fan_shells(g, case)):
        geo += ("    fan%d\n    {\n        type searchableCylinder;\n        point1 %s;\n"
                "        point2 %s;\n        radius %.6g;\n    }\n" % (i, cfdcase.v3(p1), cfdcase.v3(p2), rad))
        regions += "        fan%d { mode inside; levels ((1e15 %d)); }\n" % (i, lvl)
    text = re.sub(r"geometry\n\{\n.*?\n\}\n\ncastellatedMeshControls", "geometry\n{\n%s}\n\ncastellatedMeshControls"
                  % geo.replace("\\", "\\\\"), text, count=1, flags=re.S)
    text = re.sub(r"refinementRegions\n    \{\n.*?    \}\n", "refinementRegions\n    {\n%s    }\n" % regions,
                  text, count=1, flags=re.S)
    write_file(os.path.join(case_dir, "system/snappyHexMeshDict"), "dictionary", "snappyHexMeshDict", text)
    cfdcase.write_feature_dict(case_dir)
    cfdcase.write_common(case_dir)
    write_file(os.path.join(case_dir, "system/controlDict"), "dictionary", "controlDict",
               cfdcase.CONTROL % (STEADY_ITER, 100))
    write_file(os.path.join(case_dir, "system/fvSchemes"), "dictionary", "fvSchemes", cfdcase.SCHEMES)
    write_file(os.path.join(case_dir, "system/fvSolution"), "dictionary", "fvSolution", cfdcase.SOLUTION)
    os.makedirs(os.path.join(case_dir, "constant/triSurface"), exist_ok=True)
    with open(os.path.join(case_dir, "constant/triSurface/rod.stl"), "w") as fh:
        fh.write(rod_stl(g))
    meta = {"case": name, "from_deg": case["from_deg"], "to_deg": case["to_deg"],
            "rod_tilt_deg": math.degrees(g.t), "inlet_d_m": D, "background_cells": nbg,
            "inlet_refinement_level": g.ls, "generator_commit": git_commit_of(os.path.dirname(
                os.path.abspath(__file__)), GEN)}
    with open(os.path.join(case_dir, "case.json"), "w") as fh:
        json.dump(meta, fh, indent=1)
    print("%s: rod at %.2f deg, background %d cells" % (name, math.degrees(g.t), nbg))


def inlet(g, case_dir, tilt_deg):
    """Velocity vector, k and epsilon at the exit cap blowing at tilt_deg, from the meshed cap's
    area: u^2 A cos(delta) = K / 2 (the half domain carries half the momentum flux)."""
    vec, _, _ = patch_area(os.path.join(case_dir, "constant/polyMesh"), "rod_inlet")
    a_eff = abs(float(np.dot(vec, g.d)))
    d = direction(tilt_deg)
    cos_delta = float(np.dot(d, g.d))
    u = math.sqrt(0.5 * K_KIN / (a_eff * cos_delta))
    k = 1.5 * (INTENSITY * u) ** 2
    eps = CMU ** 0.75 * k ** 1.5 / (LSCALE * D)
    return u * d, k, eps, a_eff


def cmd_steady(name, case_dir, tilt_deg):
    """A steady run blowing at tilt_deg, the inlet ramping up as in cfdcase's cases."""
    case = find(name)
    g = geometry(case)
    bnd = read_boundary(os.path.join(case_dir, "constant/polyMesh"))
    for need in ("rod_inlet", "rod_wall", "floor", "symmetry", "atmosphere"):
        if need not in bnd:
            sys.exit("reaim: patch %s missing after meshing (have %s)" % (need, sorted(bnd)))
    uvec, k_in, eps_in, a_eff = inlet(g, case_dir, tilt_deg)
    f0 = cfdcase.RAMP_FROM
    cfdcase.write_fields(os.path.join(case_dir, "0"), "rod_inlet", cfdcase.SYMMETRY,
                         cfdcase.ramp_table(lambda f: cfdcase.v3(f * uvec)), cfdcase.v3(f0 * uvec),
                         cfdcase.ramp_table(lambda f: "%.9g" % (k_in * f ** 2)), "%.9g" % (k_in * f0 ** 2),
                         cfdcase.ramp_table(lambda f: "%.9g" % (eps_in * f ** 3)), "%.9g" % (eps_in * f0 ** 3))
    info = {"tilt_deg": tilt_deg, "inlet_area_m2": a_eff, "inlet_speed_m_s": float(np.linalg.norm(uvec)),
            "k_inlet": k_in, "epsilon_inlet": eps_in}
    with open(os.path.join(case_dir, "inlet.json"), "w") as fh:
        json.dump(info, fh, indent=1)
    print("steady at %.1f deg: inlet %.2f m/s through %.4g m^2" % (tilt_deg, info["inlet_speed_m_s"], a_eff))


def program(case):
    """The inlet's tilt over time: (t, tilt_deg) knots, held, turned at SLEW_RAD_S, held (a
    visit: held visit_s, turned back and held)."""
    a, b = case["from_deg"], case["to_deg"]
    slew = math.radians(abs(b - a)) / SLEW_RAD_S
    n = max(2, int(math.ceil(slew / 0.002)))
    knots = [(0.0, a)]
    for i in range(n + 1):
        f = i / n
        knots.append((HOLD_BEFORE_S + f * slew, a + f * (b - a)))
    if "visit_s" in case:
        back = HOLD_BEFORE_S + slew + case["visit_s"]
        for i in range(n + 1):
            f = i / n
            knots.append((back + f * slew, b + f * (a - b)))
        last, last_tilt = back + slew + VISIT_AFTER_S, a
    else:
        last, last_tilt = HOLD_BEFORE_S + slew + case.get("hold_after_s", HOLD_AFTER_S), b
    end = PROBE_DT * math.ceil(last / PROBE_DT - 1e-9)
    knots.append((end, last_tilt))
    return knots, slew, end


def probe_points():
    return [(x, y, z) for z in PROBE_Z for y in PROBE_Y for x in PROBE_X]


def probes_entry(name, fields, pts):
    s = "    %s\n    {\n        type probes;\n        libs (\"libsampling.so\");\n" % name
    s += "        executeControl adjustableRunTime;\n        executeInterval %g;\n" % PROBE_DT
    s += "        writeControl adjustableRunTime;\n        writeInterval %g;\n" % PROBE_DT
    s += "        fields (%s);\n        probeLocations\n        (\n" % " ".join(fields)
    s += "".join("            (%.6f %.6f %.6f)\n" % p for p in pts)
    return s + "        );\n    }\n"


def replace_inlet_table(text, table):
    pat = re.compile(r"(rod_inlet\s*\{[^}]*?uniformValue\s+table)\s*\d*\s*\((?:[^;]*)\)\s*;", re.S)
    new, count = pat.subn(lambda m: "%s (%s);" % (m.group(1), table), text, count=1)
    if count != 1:
        sys.exit("reaim: no rod_inlet uniformValue table in a field file")
    return new


def cmd_transient(name, src_dir, case_dir):
    """The transient case: src_dir's converged steady fields (blowing at the first tilt) at t = 0,
    the inlet following program()."""
    case = find(name)
    g = geometry(case)
    times = [d for d in os.listdir(src_dir) if re.fullmatch(r"[0-9]+", d) and d != "0"]
    if not times:
        sys.exit("reaim: %s: no converged steady fields (run its steady case first)" % src_dir)
    last = max(times, key=int)
    os.makedirs(case_dir, exist_ok=True)
    for sub in ("constant", "system"):
        shutil.copytree(os.path.join(src_dir, sub), os.path.join(case_dir, sub), dirs_exist_ok=True)
    zero = os.path.join(case_dir, "0")
    shutil.copytree(os.path.join(src_dir, last), zero, dirs_exist_ok=True)
    shutil.rmtree(os.path.join(zero, "uniform"), ignore_errors=True)
    knots, slew, end = program(case)
    states = [(t,) + inlet(g, case_dir, tilt)[:3] for t, tilt in knots]
    tables = {"U": " ".join("(%.6g %s)" % (t, cfdcase.v3(u)) for t, u, _, _ in states),
              "k": " ".join("(%.6g %.9g)" % (t, k) for t, _, k, _ in states),
              "epsilon": " ".join("(%.6g %.9g)" % (t, e) for t, _, _, e in states)}
    for fld, table in tables.items():
        path = os.path.join(zero, fld)
        text = open(path).read()
        with open(path, "w") as fh:
            fh.write(replace_inlet_table(text, table))
    probes = probes_entry("floor", ["U", "k"], probe_points())
    write_file(os.path.join(case_dir, "system/controlDict"), "dictionary", "controlDict",
               CONTROL % {"end": end, "co": MAX_CO, "field_dt": FIELD_DT, "probes": probes})
    write_file(os.path.join(case_dir, "system/fvSchemes"), "dictionary", "fvSchemes", SCHEMES_TRANSIENT)
    write_file(os.path.join(case_dir, "system/fvSolution"), "dictionary", "fvSolution", SOLUTION_TRANSIENT)
    meta = json.load(open(os.path.join(src_dir, "case.json")))
    meta.update({"case": name, "from_deg": case["from_deg"], "to_deg": case["to_deg"],
                 "kind": "visit" if "visit_s" in case else "reaim",
                 "mesh_case": case["mesh"], "visit_s": case.get("visit_s"),
                 "started_from_steady_iteration": int(last), "end_time_s": end,
                 "slew_rad_s": SLEW_RAD_S, "slew_s": slew, "turn_start_s": HOLD_BEFORE_S,
                 "max_courant": MAX_CO, "probe_interval_s": PROBE_DT,
                 "program": [{"t_s": t, "tilt_deg": tilt} for t, tilt in knots],
                 "generator_commit": git_commit_of(os.path.dirname(os.path.abspath(__file__)), GEN)})
    with open(os.path.join(case_dir, "case.json"), "w") as fh:
        json.dump(meta, fh, indent=1)
    print("%s: from the steady fields at iteration %s, turning %.1f -> %.1f deg over %.3f s from %.2f s, "
          "to %.2f s" % (name, last, case["from_deg"], case["to_deg"], slew, HOLD_BEFORE_S, end))


def cmd_convert(name, case_dir, out_dir, steady_from_dir, steady_to_dir):
    meta = json.load(open(os.path.join(case_dir, "case.json")))
    pts = probe_points()
    t, U = read_probe_series(os.path.join(case_dir, "postProcessing/floor"), "U", len(pts))
    tk, K = read_probe_series(os.path.join(case_dir, "postProcessing/floor"), "k", len(pts))
    if t.size != tk.size:
        sys.exit("reaim: U and k probes disagree in their times")
    end = meta["end_time_s"]
    if t[-1] < end - 0.5 * PROBE_DT:
        sys.exit("reaim: the run reached %g s of %g; finish it before converting" % (t[-1], end))
    os.makedirs(out_dir, exist_ok=True)
    meta["csv_interval_s"] = CSV_DT
    meta["probes"] = {"x_m": [float(v) for v in PROBE_X], "y_m": PROBE_Y, "z_m": PROBE_Z}
    for key, steady_dir in (("steady_from", steady_from_dir), ("steady_to", steady_to_dir)):
        path = os.path.join(steady_dir, "run.json")
        if os.path.exists(path):
            meta[key] = json.load(open(path))
    with open(os.path.join(out_dir, name + ".json"), "w") as fh:
        json.dump(meta, fh, indent=1)
    with open(os.path.join(out_dir, name + "_floor.csv"), "w") as fh:
        fh.write("t,x_m,y_m,z_m,ux,uy,uz,k\n")
        keep = np.nonzero(np.isclose(t / CSV_DT - np.round(t / CSV_DT), 0.0, atol=1e-6))[0]
        for i in keep:
            for j, (x, y, z) in enumerate(pts):
                u = U[i, j]
                fh.write("%.3f,%.3f,%.4f,%.3f,%.3f,%.3f,%.3f,%.4f\n" % (t[i], x, y, z, u[0], u[1], u[2], K[i, j, 0]))
    print("%s: %d samples to %.2f s at %d probes" % (name, t.size, t[-1], len(pts)))


def probes_dict(pts):
    """A function-object dictionary sampling U at pts, for postProcess -func probesAll."""
    body = "type probes;\nlibs (\"libsampling.so\");\nfields (U k);\nprobeLocations\n(\n"
    body += "".join("    (%.6f %.6f %.6f)\n" % p for p in pts)
    return body + ");\n"


def cmd_sample_steady(case_dir):
    out = os.path.join(case_dir, "postProcessing/probesAll")
    if not os.path.isdir(out):
        write_file(os.path.join(case_dir, "system/probesAll"), "dictionary", "probesAll",
                   probes_dict(probe_points()))
        env = dict(os.environ, WM_PROJECT_DIR="/usr/share/openfoam")
        run = subprocess.run(["nice", "-n", "19", "postProcess", "-func", "probesAll", "-latestTime"],
                             cwd=case_dir, capture_output=True, text=True, env=env)
        if run.returncode != 0:
            sys.exit("reaim: postProcess failed in %s: %s" % (case_dir, run.stdout.strip()[-300:]))
    times = os.listdir(out)
    if not times:
        sys.exit("reaim: %s: no probes written" % out)
    path = os.path.join(out, max(times, key=float), "U")
    vals = [line for line in open(path) if not line.startswith("#") and line.strip()]
    if not vals:
        sys.exit("reaim: %s: empty" % path)
    data = np.array(vals[-1].replace("(", " ").replace(")", " ").split()[1:], dtype=float)
    n = len(probe_points())
    if data.size != 3 * n:
        sys.exit("reaim: %s: %d values, expected %d" % (path, data.size, 3 * n))
    return data.reshape(n, 3)


def read_floor_csv(path):
    """The converted probes: times (nt,), points (n, 3), horizontal air (nt, n, 2)."""
    raw = np.genfromtxt(path, delimiter=",", names=True)
    times = np.unique(raw["t"])
    n = raw.size // times.size
    if n * times.size != raw.size:
        sys.exit("reaim: %s: %d rows are not whole records" % (path, raw.size))
    pts = np.stack([raw["x_m"][:n], raw["y_m"][:n], raw["z_m"][:n]], axis=1)
    u = np.stack([raw["ux"], raw["uy"]], axis=1).reshape(times.size, n, 2)
    return times, pts, u


def run_probe(airtwin, work, name, program_csv, points_csv, end, interval, extra):
    out = os.path.join(work, name + ".csv")
    cmd = [airtwin, "probe", "--program", program_csv, "--points", points_csv, "--end", "%g" % end,
           "--interval", "%g" % interval, "--out", out] + extra
    run = subprocess.run(cmd, capture_output=True, text=True)
    if run.returncode != 0:
        sys.exit("reaim: %s failed: %s" % (" ".join(cmd), run.stderr.strip()))
    raw = np.genfromtxt(out, delimiter=",", names=True)
    times = np.unique(raw["t_s"])
    n = raw.size // times.size
    return times, np.stack([raw["ux"], raw["uy"]], axis=1).reshape(times.size, n, 2)


SCALES = [0.125, 0.25, 0.5, 1.0, 2.0]
TRANSITS = [0.2, 0.15]    # s: free-jet transits tried beside the start-up's (0.27 s)
MIN_CHANGE = 0.5          # m/s: points where the air changes less are left out of g
R_BAND = (0.1, 0.7)       # m from the new s: where the Appendix D objects start (0.2-0.58 m)


CARRIED_COUNTER = [0.2, 1.0]         # counter-flow weights tried beside the default 0
CARRIED_CO = [0.5]         # co-flow weights tried beside the default 1
BAND_VARIANTS = ("still, no formation", "still, formation x0.5", "carried, no formation",
                 "carried, formation x0.5")


def downstream(meta, pts, s_to):
    """The points on the new s's far side from the old s (pan 0: both on the x axis)."""
    s_from = H * math.tan(math.radians(meta["from_deg"]))
    return (pts[:, 0] - s_to) * (s_to - s_from) >= 0.0


def share(u, ua, ub):
    """g: the share of the change from ua to ub that u has made, per time and point."""
    d = ub - ua
    return np.einsum("tpk,pk->tp", u - ua[None], d) / np.einsum("pk,pk->p", d, d)[None]


def rise_times(t, g, levels=(0.25, 0.5, 0.75)):
    """Per point the first time g reaches each level (nan if never)."""
    out = np.full((len(levels), g.shape[1]), np.nan)
    for li, lv in enumerate(levels):
        above = g >= lv
        hit = above.any(axis=0)
        first = np.argmax(above, axis=0)
        for p in np.nonzero(hit)[0]:
            i = first[p]
            if i == 0:
                out[li, p] = t[0]
            else:
                out[li, p] = t[i - 1] + (lv - g[i - 1, p]) / (g[i, p] - g[i - 1, p]) * (t[i] - t[i - 1])
    return out


def before_turn(meta, t, u):
    """A transient's air over the 50 ms before its turn: the steady state it started from."""
    turn = meta["turn_start_s"]
    return u[(t > turn - 0.05) & (t <= turn + 1e-9)].mean(axis=0)


def steady_air(spec, data_dir, meta):
    """The steady air at the second tilt at the probes: from a finished steady run's directory, or,
    given as data:CASE, from the converted transient CASE in data_dir that started from that
    steady state on the same mesh (its record before its turn), so the committed data suffice."""
    if not spec.startswith("data:"):
        return cmd_sample_steady(spec)[:, :2]
    name = spec[len("data:"):]
    path = os.path.join(data_dir, name + ".json")
    if not os.path.exists(path) or not os.path.exists(os.path.join(data_dir, name + "_floor.csv")):
        sys.exit("reaim: %s: no converted case %s (%s.json and %s_floor.csv) in %s" %
                 (spec, name, name, name, data_dir))
    other = json.load(open(path))
    def mesh(m):
        return m.get("mesh_case") or m["case"]
    if mesh(other) != mesh(meta) or other["from_deg"] != meta["to_deg"]:
        sys.exit("reaim: %s does not start steady at %g deg on %s's mesh" %
                 (name, meta["to_deg"], mesh(meta)))
    t, _, u = read_floor_csv(os.path.join(data_dir, name + "_floor.csv"))
    return before_turn(other, t, u)


def cfd_ends(meta, t, u_cfd, steady_to, data_dir):
    """The CFD's old air (its mean over the 50 ms before the turn) and new air (the steady state at
    the second tilt, steady_air())."""
    ub = steady_air(steady_to, data_dir, meta)
    if ub.shape[0] != u_cfd.shape[1]:
        sys.exit("reaim: the steady case's probes are not the transient's")
    return before_turn(meta, t, u_cfd), ub


def write_program(path, program, shift_s=0.0):
    """An `airtwin probe` program (pan 0) from a case's (t, tilt) knots, earlier by shift_s."""
    with open(path, "w") as fh:
        fh.write("t_s,pan_deg,tilt_deg\n")
        for k in program:
            fh.write("%.6f,0,%.6f\n" % (k["t_s"] - shift_s, k["tilt_deg"]))
    return path


def twin_setup(airtwin, out_dir, meta, pts, dt):
    """The probe points' CSV and the twin's air there held at the second tilt."""
    os.makedirs(out_dir, exist_ok=True)
    points_csv = os.path.join(out_dir, "points.csv")
    with open(points_csv, "w") as fh:
        fh.write("x_m,y_m,z_m\n")
        for p in pts:
            fh.write("%.4f,%.4f,%.4f\n" % tuple(p))
    held_csv = write_program(os.path.join(out_dir, "held.csv"),
                             [{"t_s": 0.0, "tilt_deg": meta["to_deg"]}])
    _, ub = run_probe(airtwin, out_dir, "twin_held", held_csv, points_csv, dt, dt, [])
    return points_csv, ub[-1]


def cmd_compare(name, data_dir, steady_to_dir, airtwin, out_dir, png=None):
    meta = json.load(open(os.path.join(data_dir, name + ".json")))
    t, pts, u_cfd = read_floor_csv(os.path.join(data_dir, name + "_floor.csv"))
    ua_cfd, ub_cfd = cfd_ends(meta, t, u_cfd, steady_to_dir, data_dir)
    turn = meta["turn_start_s"]
    os.makedirs(out_dir, exist_ok=True)
    # The twin's transit is the start-up's (the head of a jet starting into still air, in whole
    # steps); a turning jet is already established and may carry its turn down faster. Other
    # transits T are tried by running the program earlier by the difference.
    axis = json.load(open(os.path.join(data_dir, "startup_tilt00_d40.json")))["figures"]["axis"]
    step = 0.0025
    startup_transit = round(min(axis, key=lambda e: e["z_m"])["arrival_s"] / step) * step
    programs = {}
    for transit in [startup_transit] + TRANSITS:
        programs[transit] = write_program(
            os.path.join(out_dir, "program_transit%03.0fms.csv" % (1000 * transit)), meta["program"],
            startup_transit - transit)
    dt = float(np.round(t[1] - t[0], 6))
    end = float(t[-1])
    points_csv, ub_twin = twin_setup(airtwin, out_dir, meta, pts, dt)
    # the twin's variants: the front of still air or carried by the old air (sim/air_transport.h;
    # the default carried x1, held back x0), without the formation or at some of its times; other
    # transits with the still front
    still = ["--air-front-co-flow", "0"]
    formations = [("no formation", ["--no-air-formation"])] + [
        ("formation x%g" % f, ["--air-formation", "--air-formation-time-scale", "%g" % f])
        for f in SCALES]
    variants = [(startup_transit, "still, " + fl, still + fx) for fl, fx in formations]
    variants += [(startup_transit, "carried, " + fl, fx) for fl, fx in formations]
    variants += [(startup_transit, "carried, held back x%g, formation x0.5" % b,
                  ["--air-front-counter-flow", "%g" % b]) for b in CARRIED_COUNTER]
    variants += [(startup_transit, "carried x%g, formation x0.5" % a, ["--air-front-co-flow", "%g" % a])
                 for a in CARRIED_CO]
    variants += [(transit, "still, %s, transit %.2f s" % (fl, transit), still + fx)
                 for transit in TRANSITS for fl, fx in formations if fl in ("no formation", "formation x0.5")]
    twin = {}
    for transit, label, extra in variants:
        tt, u = run_probe(airtwin, out_dir, "twin", programs[transit], points_csv, end, dt, extra)
        idx = np.minimum(np.searchsorted(tt, t - 1e-9), tt.size - 1)
        if np.abs(tt[idx] - t).max() > 1e-6:
            sys.exit("reaim: the probe has no record at some of the CFD's times")
        twin[label] = u[idx]
    ua_twin = twin["still, no formation"][0]
    # the new s: the steady campaign's at the second tilt (pan 0: on the x axis), the twin's there
    steady_case = os.path.join(data_dir, "tilt%04.1f_mesh1_d20.json" % meta["to_deg"])
    if not os.path.exists(steady_case):
        sys.exit("reaim: %s: the steady case at the second tilt is needed" % steady_case)
    s_to = float(json.load(open(steady_case))["stagnation_point_s_m"][0])
    r = np.hypot(pts[:, 0] - s_to, pts[:, 1])
    # the steady ends against the twin's campaign air, where |u| >= 0.3 m/s
    def mape(a, b):
        m = np.linalg.norm(b, axis=1) >= 0.3
        return float(100 * np.mean(np.linalg.norm(a[m] - b[m], axis=1) / np.linalg.norm(b[m], axis=1)))
    report = {"case": name, "new_s_x_m": s_to, "startup_transit_s": startup_transit, "min_change_m_s": MIN_CHANGE, "r_band_m": list(R_BAND),
              "steady_ends": {"from_mape_pct": mape(ua_cfd, ua_twin), "to_mape_pct": mape(ub_cfd, ub_twin)},
              "heights": {}}
    after = t >= turn
    for z in sorted(set(pts[:, 2])):
        sel = (np.abs(pts[:, 2] - z) < 1e-6) & (r >= R_BAND[0]) & (r <= R_BAND[1]) & \
              (np.linalg.norm(ub_cfd - ua_cfd, axis=1) >= MIN_CHANGE) & \
              (np.linalg.norm(ub_twin - ua_twin, axis=1) >= MIN_CHANGE)
        g_cfd = share(u_cfd[:, sel], ua_cfd[sel], ub_cfd[sel])
        rt_cfd = rise_times(t, g_cfd)
        entry = {"points": int(sel.sum()), "variants": {}}
        for label, u in twin.items():
            g = share(u[:, sel], ua_twin[sel], ub_twin[sel])
            rt = rise_times(t, g)
            both = ~np.isnan(rt[1]) & ~np.isnan(rt_cfd[1])
            rise = (rt[2] - rt[0])[both]
            rise_cfd = (rt_cfd[2] - rt_cfd[0])[both]
            entry["variants"][label] = {
                "rms_g": float(np.sqrt(np.mean((g[after] - g_cfd[after]) ** 2))),
                "half_time_bias_s": float(np.mean(rt[1][both] - rt_cfd[1][both])),
                "half_time_rms_s": float(np.sqrt(np.mean((rt[1][both] - rt_cfd[1][both]) ** 2))),
                "rise_25_75_median_s": float(np.nanmedian(rise)) if rise.size else None,
                "cfd_rise_25_75_median_s": float(np.nanmedian(rise_cfd)) if rise_cfd.size else None,
                "points_timed": int(both.sum())}
        # by side of the new s (downstream: away from the old s) and distance, the twin with the
        # start-up's transit
        bands = []
        down = downstream(meta, pts, s_to)
        for side, mask in (("downstream", down), ("upstream", ~down)):
            for lo, hi in ((0.1, 0.2), (0.2, 0.4), (0.4, 0.7)):
                part = (mask & (r >= lo) & (r < hi))[sel]
                if not part.any():
                    continue
                band = {"side": side, "r_m": [lo, hi], "points": int(part.sum()),
                        "cfd_rise_25_75_median_s": float(np.nanmedian((rt_cfd[2] - rt_cfd[0])[part]))}
                for label in BAND_VARIANTS:
                    g = share(twin[label][:, sel], ua_twin[sel], ub_twin[sel])
                    rt = rise_times(t, g)
                    band[label] = {"half_time_bias_s": float(np.nanmean((rt[1] - rt_cfd[1])[part])),
                                   "rise_25_75_median_s": float(np.nanmedian((rt[2] - rt[0])[part]))}
                bands.append(band)
        entry["bands"] = bands
        best = min(entry["variants"], key=lambda k: entry["variants"][k]["rms_g"])
        entry["best"] = best
        # the timing: the new air's half-way time and its 25-75 % rise, both against the CFD's
        def timing(v):
            if v["rise_25_75_median_s"] is None or v["cfd_rise_25_75_median_s"] is None:
                return float("inf")
            return math.hypot(v["half_time_bias_s"], v["rise_25_75_median_s"] - v["cfd_rise_25_75_median_s"])
        for v in entry["variants"].values():
            v["timing_error_s"] = timing(v)
        entry["best_timing"] = min(entry["variants"], key=lambda k: entry["variants"][k]["timing_error_s"])
        report["heights"]["%g" % z] = entry
    with open(os.path.join(out_dir, "report.json"), "w") as fh:
        json.dump(report, fh, indent=1)
    print("steady ends against the twin's campaign air: from %.1f %%, to %.1f %% MAPE" %
          (report["steady_ends"]["from_mape_pct"], report["steady_ends"]["to_mape_pct"]))
    for z, e in report["heights"].items():
        print("height %s m, %d points %g-%g m from the new s (x %.2f m):" % (z, e["points"], R_BAND[0],
                                                                               R_BAND[1], s_to))
        for label, v in e["variants"].items():
            print("  %-18s rms g %.3f, half-time bias %+.3f s (rms %.3f), 25-75 %% rise %.3f s (CFD %.3f)"
                  % (label, v["rms_g"], v["half_time_bias_s"], v["half_time_rms_s"],
                     v["rise_25_75_median_s"] or float("nan"), v["cfd_rise_25_75_median_s"] or float("nan")))
        for b in e["bands"]:
            print("  %s %.1f-%.1f m (%d points): CFD rise %.3f s; half-way bias / rise: %s" % (
                b["side"], b["r_m"][0], b["r_m"][1], b["points"], b["cfd_rise_25_75_median_s"],
                ", ".join("%s %+.3f / %.3f s" % (k, b[k]["half_time_bias_s"], b[k]["rise_25_75_median_s"])
                          for k in BAND_VARIANTS)))
        print("  closest over the whole change (rms g): %s" % e["best"])
        print("  closest in timing (half-way time and 25-75 %% rise): %s" % e["best_timing"])
    if png:
        shown = ["still, no formation", "carried, formation x0.5"]
        shown += [e["best_timing"] for e in report["heights"].values() if e["best_timing"] not in shown][:1]
        plot_compare(png, t, pts, s_to, u_cfd, ua_cfd, ub_cfd, twin, ua_twin, ub_twin, meta, shown)


CARRIED = [(0.0, 0.0), (0.5, 0.0), (1.0, 0.0), (1.0, 0.2), (0.75, 0.2), (1.0, 1.0)]
PATH_SAMPLES = 60         # samples of the old air along the new front's path from the new s


def cmd_carried(name, data_dir, steady_to_dir, airtwin, out_dir):
    """The new wall jet's front carried by the old air: per probe point of a re-aim, the lag from
    the new s with the front's speed u_f(r) + a max(u_old . e, 0) + b min(u_old . e, 0) (u_f the
    start-up's front speed in still air, u_old the first tilt's steady air along the straight path
    from the new s, e its direction; a = b = 0 is the twin's lag) against the CFD's half-way
    times. The twin's own half-way times (no formation) are shifted by the lag's change."""
    sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(airtwin)), "python"))
    import airtwin as at  # the bindings beside the binary (build/python)
    meta = json.load(open(os.path.join(data_dir, name + ".json")))
    t, pts, u_cfd = read_floor_csv(os.path.join(data_dir, name + "_floor.csv"))
    ua_cfd, ub_cfd = cfd_ends(meta, t, u_cfd, steady_to_dir, data_dir)
    os.makedirs(out_dir, exist_ok=True)
    program_csv = write_program(os.path.join(out_dir, "program.csv"), meta["program"])
    dt = float(np.round(t[1] - t[0], 6))
    points_csv, ub_twin = twin_setup(airtwin, out_dir, meta, pts, dt)
    tt, u = run_probe(airtwin, out_dir, "twin", program_csv, points_csv, float(t[-1]), dt,
                      ["--no-air-formation", "--air-front-co-flow", "0"])
    u_twin = u[np.minimum(np.searchsorted(tt, t - 1e-9), tt.size - 1)]
    ua_twin = u_twin[0]
    s_to = float(json.load(open(os.path.join(data_dir, "tilt%04.1f_mesh1_d20.json" % meta["to_deg"])))
                 ["stagnation_point_s_m"][0])
    start = json.load(open(os.path.join(data_dir, "startup_tilt00_d40.json")))["figures"]["floor"]
    field = at.CfdField.read_dir(data_dir)
    r = np.hypot(pts[:, 0] - s_to, pts[:, 1])
    report = {"case": name, "laws": []}
    for z in sorted(set(pts[:, 2])):
        sel = (np.abs(pts[:, 2] - z) < 1e-6) & (r >= R_BAND[0]) & (r <= R_BAND[1]) & \
              (np.linalg.norm(ub_cfd - ua_cfd, axis=1) >= MIN_CHANGE) & \
              (np.linalg.norm(ub_twin - ua_twin, axis=1) >= MIN_CHANGE)
        half_cfd = rise_times(t, share(u_cfd[:, sel], ua_cfd[sel], ub_cfd[sel]))[1]
        half_twin = rise_times(t, share(u_twin[:, sel], ua_twin[sel], ub_twin[sel]))[1]
        arr = np.array([(e["r_m"], e["arrival_s"]) for e in start
                        if abs(e["height_m"] - z) < 1e-6 and e.get("arrival_s")])
        arr = arr[np.concatenate([[True], np.diff(arr[:, 1]) > 1e-9])]
        u_front = 1.0 / np.maximum(np.gradient(arr[:, 1], arr[:, 0]), 1e-3)
        pp = pts[sel]
        rp = r[sel]
        paths = []
        for p in pp:
            d = p[:2] - np.array([s_to, 0.0])
            e = d / np.linalg.norm(d)
            rs = (np.arange(PATH_SAMPLES) + 0.5) * np.linalg.norm(d) / PATH_SAMPLES
            u_old = field.velocity(0.0, meta["from_deg"], np.array([s_to, 0.0])[None] + rs[:, None] * e[None], z) @ e
            paths.append((np.linalg.norm(d) / PATH_SAMPLES, u_old, np.interp(rs, arr[:, 0], u_front)))
        down = downstream(meta, pp, s_to)
        ok = ~np.isnan(half_cfd) & ~np.isnan(half_twin)
        lag_still = np.array([np.sum(dr / uf) for dr, _, uf in paths])
        for co, counter in CARRIED:
            # a front held back to 5 cm/s stalls: the history keeps 2 s of orientations
            lag = np.array([min(2.0, np.sum(dr / np.maximum(uf + co * np.maximum(uo, 0) +
                                                             counter * np.minimum(uo, 0), 0.05)))
                            for dr, uo, uf in paths])
            half = half_twin + lag - lag_still
            law = {"height_m": z, "co_flow": co, "counter_flow": counter, "points": int(ok.sum()),
                   "half_time_bias_s": float(np.mean((half - half_cfd)[ok])),
                   "half_time_rms_s": float(np.sqrt(np.mean((half - half_cfd)[ok] ** 2))), "bands": []}
            for side, m in (("downstream", down), ("upstream", ~down)):
                for lo, hi in ((0.1, 0.2), (0.2, 0.4), (0.4, 0.7)):
                    part = ok & m & (rp >= lo) & (rp < hi)
                    if part.any():
                        law["bands"].append({"side": side, "r_m": [lo, hi], "points": int(part.sum()),
                                             "half_time_bias_s": float(np.mean((half - half_cfd)[part]))})
            report["laws"].append(law)
    with open(os.path.join(out_dir, "carried.json"), "w") as fh:
        json.dump(report, fh, indent=1)
    print("%s: the new front's lag with the old air's component along its path; half-way time less "
          "the CFD's (mean over the points)" % name)
    for law in report["laws"]:
        print("  %g m, co-flow x%g, counter-flow x%g: bias %+.3f s, rms %.3f s; %s" % (
            law["height_m"], law["co_flow"], law["counter_flow"], law["half_time_bias_s"], law["half_time_rms_s"],
            ", ".join("%s %.1f-%.1f %+.3f" % (b["side"][:2], b["r_m"][0], b["r_m"][1], b["half_time_bias_s"])
                      for b in law["bands"])))


VISIT_BANDS = ((0.0, 0.1), (0.1, 0.2), (0.2, 0.4), (0.4, 0.7))


def cmd_compare_visit(name, data_dir, case_dir, steady_to_dir, airtwin, out_dir, png=None):
    """A visit (the jet held visit_s at the second tilt and turned back) against the twin's moving
    air: per point the largest share g of the visited tilt's steady air the visit brings, and
    when; from the converted data when the run is done, else from the running case's probes."""
    csv = os.path.join(data_dir, name + "_floor.csv")
    if os.path.exists(csv):
        meta = json.load(open(os.path.join(data_dir, name + ".json")))
        t, pts, u_cfd = read_floor_csv(csv)
    else:
        meta = json.load(open(os.path.join(case_dir, "case.json")))
        pts = np.array(probe_points())
        t, u_cfd = read_probe_series(os.path.join(case_dir, "postProcessing/floor"), "U", len(pts),
                                     running=True)
        u_cfd = u_cfd[:, :, :2]
    if meta.get("kind") != "visit":
        sys.exit("reaim: %s is not a visit" % name)
    ua_cfd, ub_cfd = cfd_ends(meta, t, u_cfd, steady_to_dir, data_dir)
    os.makedirs(out_dir, exist_ok=True)
    program_csv = write_program(os.path.join(out_dir, "program.csv"), meta["program"])
    dt = PROBE_DT
    end = float(t[-1])
    points_csv, ub_twin = twin_setup(airtwin, out_dir, meta, pts, dt)
    still = ["--air-front-co-flow", "0"]
    variants = {"still, no formation": still + ["--no-air-formation"],
                "still, formation x0.5": still, "still, formation x1": still + ["--air-formation-time-scale", "1"],
                "carried, no formation": ["--no-air-formation"], "carried, formation x0.5 (default)": []}
    twin = {}
    for label, extra in variants.items():
        tt, u = run_probe(airtwin, out_dir, "twin", program_csv, points_csv, end, dt, extra)
        idx = np.minimum(np.searchsorted(tt, t - 1e-9), tt.size - 1)
        twin[label] = u[idx]
    ua_twin = twin["still, no formation"][0]
    steady_case = os.path.join(data_dir, "tilt%04.1f_mesh1_d20.json" % meta["to_deg"])
    s_to = float(json.load(open(steady_case))["stagnation_point_s_m"][0])
    r = np.hypot(pts[:, 0] - s_to, pts[:, 1])
    report = {"case": name, "visited_s_x_m": s_to, "visit_s": meta["visit_s"], "cfd_until_s": end,
              "min_change_m_s": MIN_CHANGE, "heights": {}}
    for z in sorted(set(pts[:, 2])):
        sel = (np.abs(pts[:, 2] - z) < 1e-6) & (r <= VISIT_BANDS[-1][1]) & \
              (np.linalg.norm(ub_cfd - ua_cfd, axis=1) >= MIN_CHANGE) & \
              (np.linalg.norm(ub_twin - ua_twin, axis=1) >= MIN_CHANGE)
        g_cfd = share(u_cfd[:, sel], ua_cfd[sel], ub_cfd[sel])
        peak_cfd = g_cfd.max(axis=0)
        when_cfd = t[g_cfd.argmax(axis=0)]
        down = downstream(meta, pts, s_to)[sel]
        rs = r[sel]
        entry = {"points": int(sel.sum()), "bands": []}
        peaks = {label: share(u[:, sel], ua_twin[sel], ub_twin[sel]) for label, u in twin.items()}
        for side, mask in (("downstream", down), ("upstream", ~down)):
            for lo, hi in VISIT_BANDS:
                part = mask & (rs >= lo) & (rs < hi)
                if not part.any():
                    continue
                band = {"side": side, "r_m": [lo, hi], "points": int(part.sum()),
                        "cfd": {"peak_g_median": float(np.median(peak_cfd[part])),
                                "peak_time_median_s": float(np.median(when_cfd[part]))}}
                for label, g in peaks.items():
                    band[label] = {"peak_g_median": float(np.median(g.max(axis=0)[part])),
                                   "peak_time_median_s": float(np.median(t[g.argmax(axis=0)][part])),
                                   "rms_g": float(np.sqrt(np.mean((g[:, part] - g_cfd[:, part]) ** 2)))}
                entry["bands"].append(band)
        report["heights"]["%g" % z] = entry
    with open(os.path.join(out_dir, "report.json"), "w") as fh:
        json.dump(report, fh, indent=1)
    print("%s: the CFD to %.2f s; the visited s at x %.2f m; peak share g of the visited air (median) "
          "and its time" % (name, end, s_to))
    for z, e in report["heights"].items():
        print("height %s m, %d points:" % (z, e["points"]))
        for b in e["bands"]:
            print("  %-10s %.1f-%.1f m (%3d): CFD %.2f at %.2f s; %s" % (
                b["side"], b["r_m"][0], b["r_m"][1], b["points"], b["cfd"]["peak_g_median"],
                b["cfd"]["peak_time_median_s"],
                "; ".join("%s %.2f at %.2f s (rms g %.2f)" % (k, b[k]["peak_g_median"], b[k]["peak_time_median_s"],
                                                               b[k]["rms_g"]) for k in variants)))
    if png:
        plot_compare(png, t, pts, s_to, u_cfd, ua_cfd, ub_cfd, twin, ua_twin, ub_twin, meta,
                     list(variants))


def plot_compare(png, t, pts, s_to, u_cfd, ua_cfd, ub_cfd, twin, ua_twin, ub_twin, meta, shown):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    picks = []
    away = 1.0 if meta["to_deg"] >= meta["from_deg"] else -1.0  # downstream: away from the old s
    for dx in (-0.3, 0.2, 0.4, 0.6):
        want = np.array([s_to + away * dx, 0.0005, 0.004])
        picks.append((dx, int(np.argmin(np.linalg.norm(pts - want, axis=1)))))
    fig, axes = plt.subplots(1, len(picks), figsize=(4 * len(picks), 3.4), sharey=True)
    for ax, (dx, i) in zip(axes, picks):
        g = lambda u, ua, ub: (u[:, i] - ua[i]) @ (ub[i] - ua[i]) / np.dot(ub[i] - ua[i], ub[i] - ua[i])
        ax.plot(t, g(u_cfd, ua_cfd, ub_cfd), "k-", lw=2, label="CFD (3-D re-aim)")
        for k, label in enumerate(shown):
            ax.plot(t, g(twin[label], ua_twin, ub_twin), "C%d%s" % (k, "--" if k == 0 else "-"),
                    label="twin, " + label)
        ax.axvline(meta["turn_start_s"], color="0.6", lw=0.8)
        ax.set_title("x = %.2f m (%+.1f m from the new s), 4 mm" % (pts[i, 0], dx), fontsize=9)
        ax.set_xlabel("t (s)")
        ax.grid(alpha=0.3)
    axes[0].set_ylabel("share of the change to the new air")
    axes[-1].legend(fontsize=7, loc="lower right")
    fig.suptitle("Re-aim %g -> %g deg at 7 rad/s: the floor air's change, CFD against the twin" %
                 (meta["from_deg"], meta["to_deg"]), fontsize=10)
    fig.tight_layout()
    fig.savefig(png, dpi=90)


def main(argv):
    if len(argv) == 2 and argv[1] == "list":
        for c in cases():
            print("%s %g %g %s" % (c["name"], c["from_deg"], c["to_deg"], c["mesh"]))
    elif len(argv) == 4 and argv[1] == "write":
        cmd_write(argv[2], argv[3])
    elif len(argv) == 5 and argv[1] == "steady":
        cmd_steady(argv[2], argv[3], float(argv[4]))
    elif len(argv) == 5 and argv[1] == "transient":
        cmd_transient(argv[2], argv[3], argv[4])
    elif len(argv) == 3 and argv[1] == "progress":
        startup_progress(argv[2])
    elif len(argv) == 7 and argv[1] == "convert":
        cmd_convert(argv[2], argv[3], argv[4], argv[5], argv[6])
    elif len(argv) == 3 and argv[1] == "sample-steady":
        print("%d probes" % len(cmd_sample_steady(argv[2])))
    elif len(argv) == 7 and argv[1] == "carried":
        cmd_carried(argv[2], argv[3], argv[4], argv[5], argv[6])
    elif len(argv) in (8, 10) and argv[1] == "compare-visit":
        png = argv[9] if len(argv) == 10 and argv[8] == "--png" else None
        if len(argv) == 10 and png is None:
            sys.exit(__doc__)
        cmd_compare_visit(argv[2], argv[3], argv[4], argv[5], argv[6], argv[7], png)
    elif len(argv) in (7, 9) and argv[1] == "compare":
        png = argv[8] if len(argv) == 9 and argv[7] == "--png" else None
        if len(argv) == 9 and png is None:
            sys.exit(__doc__)
        cmd_compare(argv[2], argv[3], argv[4], argv[5], argv[6], png)
    else:
        sys.exit(__doc__)


if __name__ == "__main__":
    main(sys.argv)
