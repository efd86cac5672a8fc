#!/usr/bin/python3
"""Validation of the CFD campaign against published facts (docs/cfd.md), from data/cfd/ alone.

Usage: /usr/bin/python3 scripts/cfd/analyse.py [--data DIR] [--img DIR] [--json FILE]
Prints a Markdown summary; writes data/cfd/validation.json and, with matplotlib, docs/img/cfd_*.png.
Computed here:
  - stagnation point s (zero of ux on the symmetry line at z = 1.5 cm, the minimum of the in-plane
    speed) and |c - s| against eq. (2) of the paper, a1 |c|^a2 with a1 = 0.1, a2 = 2.33;
  - the free jet's centreline decay U_c = B sqrt(4K/pi) / (s - s0) (B ~ 6 for round jets);
  - the wall jet's maximum speed against Poreh, Tsuei & Cermak (1967): u_max H / sqrt(K) = 1.32 (r/H)^-1.1;
  - the peak floor speed at 1.5 cm per tilt against the paper's ~3.4 m/s;
  - mesh and inlet independence: MAPE of the in-plane floor speed where |u| >= 0.3 m/s.
"""
import argparse
import json
import math
import os
import sys

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
TOP = os.path.dirname(os.path.dirname(HERE))
H = 1.43
A1, A2 = 0.1, 2.33
MASK = 0.3


def load_case(data, name):
    hdr = json.load(open(os.path.join(data, name + ".json")))
    arr = None
    f32 = os.path.join(data, hdr["data_file"])
    if os.path.exists(f32):
        arr = np.fromfile(f32, dtype="<f4").reshape(hdr["shape"])
    csv = {}
    for key, fn in hdr.get("csv", {}).items():
        p = os.path.join(data, fn)
        if os.path.exists(p):
            csv[key] = np.genfromtxt(p, delimiter=",", names=True)
    return hdr, arr, csv


def inplane(hdr, arr, height=0.015):
    hi = hdr["grid"]["heights_m"].index(height)
    f = hdr["fields"]
    return np.hypot(arr[hi, f.index("ux")], arr[hi, f.index("uy")])


def stagnation(hdr, csv):
    """s on the symmetry line: where ux changes sign from - to + nearest c (linear interpolation)."""
    c = hdr["projection_point_c_m"][0]
    ax = csv["axisline"]
    x, ux = ax["x_m"], ax["ux_m_s"]
    best = None
    for i in range(len(x) - 1):
        if ux[i] < 0 <= ux[i + 1] and abs(x[i] - c) < 1.0:
            xs = x[i] - ux[i] * (x[i + 1] - x[i]) / (ux[i + 1] - ux[i])
            if best is None or abs(xs - c) < abs(best - c):
                best = xs
    return best


def stagnation_grid(hdr, arr):
    """Floor-grid point of minimum in-plane speed within 0.5 m of c at z = 1.5 cm (1 cm pitch)."""
    c = hdr["projection_point_c_m"][0]
    g = hdr["grid"]
    sp = inplane(hdr, arr)
    x = g["x0_m"] + g["dx_m"] * np.arange(g["nx"])
    y = g["y0_m"] + g["dy_m"] * np.arange(g["ny"])
    y[0] = g["row_iy0_sampled_at_y_m"]
    xx, yy = np.meshgrid(x, y)
    near = np.hypot(xx - c, yy) < 0.5
    if not near.any():
        return None
    sp = np.where(near, sp, np.inf)
    k = int(np.argmin(sp))
    return float(xx.flat[k]), float(yy.flat[k]), float(sp.flat[k])


def centreline_fit(hdr, csv, lo=0.4, hi_frac=0.7):
    """Fit 1/U_c = (s - s0) / (B J) over s in [lo, hi_frac * L]; J = sqrt(4K/pi)."""
    K = hdr["inlet"]["momentum_flux_kinematic_m4_s2"]
    J = math.sqrt(4.0 * K / math.pi)
    cl = csv["centreline"]
    s, u = cl["s_m"], cl["u_axial_m_s"]
    L = H / math.cos(math.radians(hdr["tilt_deg"]))
    sel = (s >= lo) & (s <= hi_frac * L) & (u > 0)
    slope, icpt = np.polyfit(s[sel], 1.0 / u[sel], 1)
    B = 1.0 / (slope * J)
    s0 = -icpt / slope
    # local B at a few distances (with the fitted virtual origin)
    return {"B": B, "virtual_origin_m": s0, "fit_range_m": [lo, hi_frac * L], "J_m2_s": J,
            "u_at_floor_minus_10cm": float(np.interp(L - 0.10, s, u))}


def walljet_fit(hdr, csv, rlo=0.3, rhi=1.2):
    """Azimuthal mean of the wall jet's maximum speed vs r from c, against Poreh et al. (1967)."""
    K = hdr["inlet"]["momentum_flux_kinematic_m4_s2"]
    wj = csv["walljet"]
    rs = np.unique(wj["r_from_c_m"])
    um = np.array([wj["umax_m_s"][wj["r_from_c_m"] == r].mean() for r in rs])
    zm = np.array([wj["z_umax_m"][wj["r_from_c_m"] == r].mean() for r in rs])
    sel = (rs >= rlo) & (rs <= rhi)
    expo, lg = np.polyfit(np.log(rs[sel] / H), np.log(um[sel] * H / math.sqrt(K)), 1)
    poreh = 1.32 * (rs / H) ** -1.1 * math.sqrt(K) / H
    table = []
    for r in (0.3, 0.5, 0.75, 1.0, 1.25):
        i = int(np.argmin(np.abs(rs - r)))
        table.append({"r_m": float(rs[i]), "umax_m_s": float(um[i]), "z_umax_m": float(zm[i]),
                      "poreh_m_s": float(poreh[i]), "ratio": float(um[i] / poreh[i])})
    return {"exponent": expo, "coefficient": math.exp(lg), "fit_range_m": [rlo, rhi], "table": table,
            "r": rs, "umax": um, "poreh": poreh}


def mape(ref, other, mask_speed=MASK):
    sel = np.isfinite(ref) & np.isfinite(other) & (ref >= mask_speed)
    e = np.abs(other[sel] - ref[sel]) / ref[sel] * 100.0
    return {"mape_pct": float(e.mean()), "p95_pct": float(np.percentile(e, 95)), "points": int(sel.sum())}


def peak(hdr, arr, csv):
    """Peak in-plane speed at z = 1.5 cm: the grid, and the wall-jet profiles and the symmetry line
    (which reach beyond the grid at large tilt)."""
    best = (-1.0, None, None, "grid")
    if arr is not None:
        sp = inplane(hdr, arr)
        g = hdr["grid"]
        k = int(np.nanargmax(sp))
        iy, ix = divmod(k, g["nx"])
        best = (float(sp.flat[k]), g["x0_m"] + ix * g["dx_m"], g["y0_m"] + iy * g["dy_m"], "grid")
    ax = csv.get("axisline")
    if ax is not None:
        i = int(np.argmax(np.abs(ax["ux_m_s"])))
        if abs(ax["ux_m_s"][i]) > best[0]:
            best = (float(abs(ax["ux_m_s"][i])), float(ax["x_m"][i]), 0.0, "symmetry line")
    wj = csv.get("walljet")
    if wj is not None:
        i = int(np.argmax(wj["u_z015_m_s"]))
        if wj["u_z015_m_s"][i] > best[0] + 1e-9:
            c = hdr["projection_point_c_m"][0]
            a = math.radians(wj["direction_deg"][i])
            r = wj["r_from_c_m"][i]
            best = (float(wj["u_z015_m_s"][i]), c + r * math.cos(a), r * math.sin(a), "wall-jet profiles")
    return {"speed_m_s": best[0], "x_m": best[1], "y_m": best[2], "from": best[3]}


MESH_TARGET_PCT = 5.0
DOC_BEGIN = "<!-- analyse.py: begin (generated by scripts/cfd/analyse.py --doc; edit the script, not this block) -->"
DOC_END = "<!-- analyse.py: end -->"


def campaign_status(data):
    """The campaign's cases in run order (from cfdcase.py) with done / to do."""
    sys.path.insert(0, HERE)
    try:
        import cfdcase
    except ImportError:
        return []
    return [{"name": c["name"], "tilt_deg": c["tilt_deg"], "mesh_level": c["mesh_level"],
             "inlet_d_m": c["inlet_d"], "held_out": c["held_out"],
             "done": os.path.exists(os.path.join(data, c["name"] + ".json"))} for c in cfdcase.campaign()]


def offset_law(out, names):
    """|c - s| = A |c|^n fitted in log-log over the level-1, 20 mm tilts > 0 that are not held out;
    its prediction for the held-out tilts."""
    fit, held = [], []
    for n in names:
        r = out["cases"][n]
        if r["mesh_level"] != 1 or abs(r["inlet_d_m"] - 0.02) > 1e-9 or r["tilt_deg"] <= 0 or r["s_m"] is None:
            continue
        (held if r["held_out"] else fit).append((r["c_m"], r["offset_m"], n))
    if len(fit) < 2:
        return None
    cs = np.array([f[0] for f in fit])
    os_ = np.array([f[1] for f in fit])
    n_exp, lg = np.polyfit(np.log(cs), np.log(os_), 1)
    A = math.exp(lg)
    res = {"A": A, "n": n_exp, "fitted_on": [f[2] for f in fit],
           "max_abs_residual_m": float(np.max(np.abs(A * cs ** n_exp - os_))), "held_out": []}
    order = np.argsort(cs)
    cl, ol = np.concatenate([[0.0], cs[order]]), np.concatenate([[0.0], os_[order]])   # tilt 0: no offset
    for c, o, n in held:
        lin = float(np.interp(c, cl, ol))
        res["held_out"].append({"case": n, "c_m": c, "offset_m": o, "predicted_m": A * c ** n_exp,
                                "error_m": A * c ** n_exp - o, "eq2_m": A1 * c ** A2,
                                "linear_in_c_m": lin, "linear_error_m": lin - o})
    return res


def shifted_speed(hdr, arr, dx):
    """In-plane speed at 1.5 cm on the grid, taken at x + dx (linear in x; NaN off the grid)."""
    g = hdr["grid"]
    sp = inplane(hdr, arr)
    x = g["x0_m"] + g["dx_m"] * np.arange(g["nx"])
    return np.array([np.interp(x + dx, x, row, left=np.nan, right=np.nan) for row in sp])


def held_out_field(cases, out, names):
    """The held-out tilt's floor speed at 1.5 cm against its neighbouring fitted tilts, each shifted so
    that its s lands on the held-out s: linear in tilt between the two, and the nearest alone."""
    main = sorted([n for n in names if out["cases"][n]["mesh_level"] == 1
                   and abs(out["cases"][n]["inlet_d_m"] - 0.02) < 1e-9 and out["cases"][n]["s_m"] is not None
                   and cases[n][1] is not None], key=lambda n: out["cases"][n]["tilt_deg"])
    res = []
    for h in [n for n in main if out["cases"][n]["held_out"]]:
        t = out["cases"][h]["tilt_deg"]
        fit = [n for n in main if not out["cases"][n]["held_out"]]
        lo = [n for n in fit if out["cases"][n]["tilt_deg"] < t]
        hi = [n for n in fit if out["cases"][n]["tilt_deg"] > t]
        if not lo or not hi:
            continue
        lo, hi = lo[-1], hi[0]
        ref = inplane(cases[h][0], cases[h][1])
        sh = out["cases"][h]["s_m"]
        f = {}
        for n in (lo, hi):
            f[n] = shifted_speed(cases[n][0], cases[n][1], out["cases"][n]["s_m"] - sh)
        w = (t - out["cases"][lo]["tilt_deg"]) / (out["cases"][hi]["tilt_deg"] - out["cases"][lo]["tilt_deg"])
        lin = (1 - w) * f[lo] + w * f[hi]     # NaN where either is off the grid: the same points below
        ok = np.isfinite(lin)
        r = {"case": h, "between": [lo, hi], "weight_hi": w, "linear": mape(ref, lin),
             "alone": [mape(ref, np.where(ok, f[n], np.nan)) for n in (lo, hi)]}
        res.append(r)
    return res


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--data", default=os.path.join(TOP, "data/cfd"))
    ap.add_argument("--img", default=os.path.join(TOP, "docs/img"))
    ap.add_argument("--json", default=None)
    ap.add_argument("--doc", default=None,
                    help="a Markdown file whose block between the analyse.py markers is replaced by the summary")
    a = ap.parse_args()
    names = sorted(fn[:-5] for fn in os.listdir(a.data)
                   if fn.endswith(".json") and fn.startswith("tilt"))
    cases = {n: load_case(a.data, n) for n in names}
    if not cases:
        sys.exit("analyse: no cases in %s" % a.data)
    out = {"status": campaign_status(a.data), "cases": {}, "independence": {}}
    for n in names:
        hdr, arr, csv = cases[n]
        c = hdr["projection_point_c_m"][0]
        s = stagnation(hdr, csv)
        sg = stagnation_grid(hdr, arr) if arr is not None else None
        pk = peak(hdr, arr, csv)
        wt = hdr.get("wall_time_s") or {}
        rec = {"tilt_deg": hdr["tilt_deg"], "held_out": hdr.get("held_out", False), "mesh_level": hdr["mesh_level"],
               "inlet_d_m": hdr["inlet"]["diameter_m"], "inlet_speed_m_s": hdr["inlet"]["speed_m_s"],
               "inlet_area_error_pct": 100.0 * (hdr["inlet"]["half_area_m2"] / hdr["inlet"]["half_area_nominal_m2"] - 1.0),
               "cells": hdr["cells"], "iterations": hdr["iterations"],
               "converged": hdr["converged"], "final_residuals": hdr["final_residuals"],
               "wall_time_s": wt, "mpi_ranks": hdr.get("mpi_ranks"),
               "startup_ramp": bool(hdr["inlet"].get("speed_ramp")),
               "s_per_iteration": (wt["solve"] / hdr["iterations"]) if wt.get("solve") and hdr["iterations"] else None,
               "c_m": c, "s_m": s,
               "offset_m": abs(c - s) if s is not None else None, "eq2_offset_m": A1 * abs(c) ** A2,
               "s_grid_min_speed": sg, "peak_z015": pk,
               "peak_from_s_m": (math.hypot(pk["x_m"] - s, pk["y_m"]) if s is not None else None)}
        if "centreline" in csv:
            rec["centreline"] = centreline_fit(hdr, csv)
        out["cases"][n] = rec

    # wall jet at tilt 0, against Poreh et al. (1967): the fit range used throughout, and the far part only
    for n in names:
        hdr, _, csv = cases[n]
        if hdr["tilt_deg"] == 0.0 and "walljet" in csv:
            w = walljet_fit(hdr, csv)
            rec = {k: v for k, v in w.items() if k not in ("r", "umax", "poreh")}
            wf = walljet_fit(hdr, csv, 0.75, 1.5)
            rec["far"] = {"exponent": wf["exponent"], "coefficient": wf["coefficient"],
                          "fit_range_m": wf["fit_range_m"]}
            out["cases"][n]["walljet"] = rec

    # independence
    for n in names:
        hdr, arr, _ = cases[n]
        if hdr["mesh_level"] == 1 and abs(hdr["inlet"]["diameter_m"] - 0.02) < 1e-9:
            continue
        ref = "tilt%04.1f_mesh1_d20" % hdr["tilt_deg"]
        if ref not in cases or arr is None or cases[ref][1] is None:
            continue
        hr, ar, _ = cases[ref]
        if hdr["mesh_level"] == 2:
            what = "mesh 1 vs mesh 2"          # the finer mesh is the reference
        else:
            what = "inlet 20 mm vs 10 mm"      # the smaller inlet is the reference
        res = {}
        for h in (0.0075, 0.015, 0.025):
            res["z%.4f" % h] = mape(inplane(hdr, arr, h), inplane(hr, ar, h))
        sa, sb = out["cases"][n]["s_m"], out["cases"][ref]["s_m"]
        out["independence"][n] = {"what": what, "reference": n, "compared": ref, "by_height": res,
                                  "s_shift_m": (sb - sa) if sa is not None and sb is not None else None,
                                  "peak_m_s": [out["cases"][n]["peak_z015"]["speed_m_s"],
                                               out["cases"][ref]["peak_z015"]["speed_m_s"]],
                                  "centreline_B": [out["cases"][x].get("centreline", {}).get("B") for x in (n, ref)],
                                  "target_pct": MESH_TARGET_PCT,
                                  "within_target": res["z0.0150"]["mape_pct"] <= MESH_TARGET_PCT}
    out["offset_law"] = offset_law(out, names)
    out["held_out_field"] = held_out_field(cases, out, names)

    text = markdown(out, names)
    print(text)
    path = a.json or os.path.join(a.data, "validation.json")
    with open(path, "w") as fh:
        json.dump(out, fh, indent=1, default=float)
        fh.write("\n")
    if a.doc:
        doc = open(a.doc).read()
        i, j = doc.find(DOC_BEGIN), doc.find(DOC_END)
        if i < 0 or j < i:
            sys.exit("analyse: %s has no analyse.py markers" % a.doc)
        doc = doc[:i + len(DOC_BEGIN)] + "\n" + text.rstrip() + "\n" + doc[j:]
        with open(a.doc, "w") as fh:
            fh.write(doc)
    try:
        import matplotlib
        matplotlib.use("Agg")
        figures(cases, names, out, a.img)
    except ImportError:
        print("(matplotlib missing: no figures; bash scripts/setup.sh --cfd installs it)")


def _f(v, fmt):
    return fmt % v if v is not None else "-"


def markdown(out, names):
    """The summary as Markdown: status, cost, stagnation, peaks, jet laws, independence."""
    L = []
    st = out["status"]
    if st:
        done = [c for c in st if c["done"]]
        todo = [c for c in st if not c["done"]]
        L.append("**Campaign state: %d of %d cases done.**%s" % (
            len(done), len(st), (" To do: " + ", ".join("`%s`" % c["name"] for c in todo) + ".") if todo else ""))
        L.append("")
    L.append("#### Cost and convergence per case")
    L.append("")
    L.append("| case | tilt (deg) | mesh | inlet (mm) | inlet area vs nominal | inlet speed (m/s) | cells |"
             " start-up ramp | meshing (s) | solving (s) | iterations | s / iteration |"
             " converged (residuals < 1e-4) | largest final residual |")
    L.append("|---|---|---|---|---|---|---|---|---|---|---|---|---|---|")
    for n in names:
        r = out["cases"][n]
        wt = r["wall_time_s"]
        fr = r["final_residuals"] or {}
        big = max(fr.items(), key=lambda kv: kv[1]) if fr else None
        L.append("| `%s` | %g | %d | %g | %+.2f %% | %.1f | %d | %s | %s | %s | %d | %s | %s | %s |" % (
            n, r["tilt_deg"], r["mesh_level"], 1000 * r["inlet_d_m"], r["inlet_area_error_pct"],
            r["inlet_speed_m_s"], r["cells"], "yes" if r["startup_ramp"] else "no", _f(wt.get("mesh"), "%d"),
            _f(wt.get("solve"), "%d"), r["iterations"], _f(r["s_per_iteration"], "%.2f"),
            "yes" if r["converged"] else "no", "%s %.1e" % big if big else "-"))
    tm = sum((out["cases"][n]["wall_time_s"].get("mesh") or 0) for n in names)
    ts = sum((out["cases"][n]["wall_time_s"].get("solve") or 0) for n in names)
    L.append("")
    L.append("Total for these %d cases: %.0f min (meshing %.0f, solving %.0f; each solving time includes up to"
             " 30 s of the runner's polling; sampling and conversion take seconds)."
             % (len(names), (tm + ts) / 60.0, tm / 60.0, ts / 60.0))
    L.append("")

    main_names = sorted([n for n in names if out["cases"][n]["mesh_level"] == 1
                         and abs(out["cases"][n]["inlet_d_m"] - 0.02) < 1e-9],
                        key=lambda n: out["cases"][n]["tilt_deg"])
    L.append("#### Stagnation point and peak floor speed (mesh 1, 20 mm inlet)")
    L.append("")
    L.append("| tilt (deg) | c (m) | s (m) | abs(c - s), CFD (m) | eq. (2) 0.1 abs(c)^2.33 (m) | CFD / eq. (2) |"
             " peak in-plane speed at 1.5 cm (m/s) | at (x, y) (m) | peak's distance from s (m) |")
    L.append("|---|---|---|---|---|---|---|---|---|")
    for n in main_names:
        r = out["cases"][n]
        pk = r["peak_z015"]
        ratio = r["offset_m"] / r["eq2_offset_m"] if r["offset_m"] is not None and r["eq2_offset_m"] > 0 else None
        L.append("| %g%s | %.3f | %s | %s | %.3f | %s | %.2f | (%.2f, %.2f) | %s |" % (
            r["tilt_deg"], " (held out)" if r["held_out"] else "", r["c_m"], _f(r["s_m"], "%.3f"),
            _f(r["offset_m"], "%.3f"), r["eq2_offset_m"], _f(ratio, "%.2f"), pk["speed_m_s"], pk["x_m"], pk["y_m"],
            _f(r["peak_from_s_m"], "%.2f")))
    L.append("")
    ol = out.get("offset_law")
    if ol:
        L.append("Power law fitted to the CFD offsets (tilts %s): abs(c - s) = %.3f abs(c)^%.2f (largest residual %.1f cm)."
                 % (", ".join("%g" % out["cases"][n]["tilt_deg"] for n in ol["fitted_on"]), ol["A"], ol["n"],
                    100 * ol["max_abs_residual_m"]))
        for h in ol["held_out"]:
            L.append("Held-out tilt %g deg: CFD offset %.3f m; the fitted law predicts %.3f m (%+.1f cm), linear"
                     " interpolation in abs(c) between the neighbouring tilts %.3f m (%+.1f cm), eq. (2) %.3f m"
                     " (%+.1f cm)."
                     % (out["cases"][h["case"]]["tilt_deg"], h["offset_m"], h["predicted_m"], 100 * h["error_m"],
                        h["linear_in_c_m"], 100 * h["linear_error_m"], h["eq2_m"], 100 * (h["eq2_m"] - h["offset_m"])))
        L.append("")

    for h in out.get("held_out_field") or []:
        L.append("Held-out floor field: the speed at 1.5 cm of tilt %g deg against tilts %g and %g, each shifted"
                 " along x to put its s on the held-out s and mixed linearly in tilt: MAPE %.1f %% (95th percentile"
                 " %.1f %%, %d points where the held-out speed >= %.1f m/s and both are on the grid); either"
                 " alone, shifted, on the same points: %.1f %% and %.1f %%." % (
                     out["cases"][h["case"]]["tilt_deg"], out["cases"][h["between"][0]]["tilt_deg"],
                     out["cases"][h["between"][1]]["tilt_deg"], h["linear"]["mape_pct"], h["linear"]["p95_pct"],
                     h["linear"]["points"], MASK, h["alone"][0]["mape_pct"], h["alone"][1]["mape_pct"]))
        L.append("")

    L.append("#### Free jet: centreline decay constant")
    L.append("")
    L.append("U_c = B sqrt(4K/pi) / (s - s0), fitted as 1/U_c linear in the distance s from the exit over"
             " [0.4 m, 0.7 L] (L the slant distance to the floor); round free jets measure B ~ 5-6.")
    L.append("")
    L.append("| case | B | virtual origin s0 (m) | fit range (m) | U_c 10 cm above the floor (m/s) |")
    L.append("|---|---|---|---|---|")
    for n in sorted(names, key=lambda n: (out["cases"][n]["mesh_level"], -out["cases"][n]["inlet_d_m"],
                                          out["cases"][n]["tilt_deg"])):
        cl = out["cases"][n].get("centreline")
        if cl:
            L.append("| `%s` | %.2f | %.3f | %.2f-%.2f | %.2f |" % (n, cl["B"], cl["virtual_origin_m"],
                                                                   cl["fit_range_m"][0], cl["fit_range_m"][1],
                                                                   cl["u_at_floor_minus_10cm"]))
    Bs = [out["cases"][n]["centreline"]["B"] for n in main_names if "centreline" in out["cases"][n]]
    if Bs:
        L.append("")
        L.append("Mesh 1, 20 mm inlet: B from %.2f to %.2f over %d tilts (mean %.2f)." % (
            min(Bs), max(Bs), len(Bs), sum(Bs) / len(Bs)))
    L.append("")

    wj = [n for n in names if "walljet" in out["cases"][n]]
    if wj:
        L.append("#### Wall jet at tilt 0 against Poreh, Tsuei & Cermak (1967)")
        L.append("")
        L.append("Maximum in-plane speed over height, mean over the five sampled directions, as"
                 " u_max H / sqrt(K) = C (r/H)^n; Poreh et al.: C = 1.32, n = -1.1.")
        L.append("")
        L.append("| case | C, n over r 0.3-1.2 m | C, n over r 0.75-1.5 m |")
        L.append("|---|---|---|")
        for n in wj:
            w = out["cases"][n]["walljet"]
            L.append("| `%s` | %.2f, %.2f | %.2f, %.2f |" % (n, w["coefficient"], w["exponent"],
                                                          w["far"]["coefficient"], w["far"]["exponent"]))
        L.append("")
        w0 = "tilt00.0_mesh1_d20" if "tilt00.0_mesh1_d20" in wj else wj[0]
        w = out["cases"][w0]["walljet"]
        L.append("`%s`:" % w0)
        L.append("")
        L.append("| r from c (m) | u_max (m/s) | its height (mm) | Poreh (m/s) | CFD / Poreh |")
        L.append("|---|---|---|---|---|")
        for t in w["table"]:
            L.append("| %.2f | %.2f | %.1f | %.2f | %.2f |" % (t["r_m"], t["umax_m_s"], 1000 * t["z_umax_m"],
                                                             t["poreh_m_s"], t["ratio"]))
        L.append("")

    L.append("#### Mesh and inlet independence")
    L.append("")
    L.append("MAPE of the in-plane floor speed over the 1 cm grid where the reference (the finer mesh, or the"
             " smaller inlet) is >= %.1f m/s; target <= %.0f %% at 1.5 cm." % (MASK, MESH_TARGET_PCT))
    L.append("")
    if out["independence"]:
        L.append("| comparison | tilt (deg) | MAPE at 1.5 cm | 95th percentile | points | at 7.5 mm | at 2.5 cm |"
                 " within target | s, compared - reference (mm) | peak at 1.5 cm, reference / compared (m/s) | B, reference / compared |")
        L.append("|---|---|---|---|---|---|---|---|---|---|---|")
        for n, r in sorted(out["independence"].items(), key=lambda kv: (kv[1]["what"], kv[0])):
            z = r["by_height"]
            B = r["centreline_B"]
            L.append("| %s | %g | %.2f %% | %.2f %% | %d | %.2f %% | %.2f %% | %s | %s | %.2f / %.2f | %s |" % (
                r["what"], out["cases"][n]["tilt_deg"], z["z0.0150"]["mape_pct"], z["z0.0150"]["p95_pct"],
                z["z0.0150"]["points"], z["z0.0075"]["mape_pct"], z["z0.0250"]["mape_pct"],
                "yes" if r["within_target"] else "no", _f(1000 * r["s_shift_m"] if r["s_shift_m"] is not None
                                                          else None, "%+.1f"),
                r["peak_m_s"][0], r["peak_m_s"][1],
                "%.2f / %.2f" % tuple(B) if None not in B else "-"))
    else:
        L.append("No pair of cases yet.")
    L.append("")
    return "\n".join(L)


def figures(cases, names, out, img):
    import matplotlib.pyplot as plt
    os.makedirs(img, exist_ok=True)
    main_names = [n for n in names if "_mesh1_d20" in n]
    main_names.sort(key=lambda n: cases[n][0]["tilt_deg"])
    # floor speed at 1.5 cm per tilt (mirrored to y < 0)
    m = [n for n in main_names if cases[n][1] is not None]
    if m:
        ncol = min(4, len(m))
        nrow = (len(m) + ncol - 1) // ncol
        fig, axs = plt.subplots(nrow, ncol, figsize=(3.0 * ncol, 3.0 * nrow), squeeze=False)
        for ax in axs.flat:
            ax.set_visible(False)
        for ax, n in zip(axs.flat, m):
            hdr, arr, csv = cases[n]
            g = hdr["grid"]
            sp = inplane(hdr, arr)
            full = np.vstack([sp[::-1], sp[1:]])
            ext = [g["x0_m"], g["x0_m"] + (g["nx"] - 1) * g["dx_m"], -(g["ny"] - 1) * g["dy_m"],
                   (g["ny"] - 1) * g["dy_m"]]
            ax.set_visible(True)
            im = ax.imshow(full, origin="lower", extent=ext, vmin=0, vmax=4.0, cmap="viridis")
            c = hdr["projection_point_c_m"][0]
            s = out["cases"][n]["s_m"]
            if c <= ext[1]:
                ax.plot([c], [0], "w+", ms=8)
            if s is not None and s <= ext[1]:
                ax.plot([s], [0], "rx", ms=6)
            ax.set_title("tilt %g deg" % hdr["tilt_deg"], fontsize=9)
            ax.tick_params(labelsize=7)
        fig.colorbar(im, ax=axs.ravel().tolist(), shrink=0.8, label="in-plane speed at 1.5 cm (m/s)")
        fig.savefig(os.path.join(img, "cfd_floor_speed.png"), dpi=80)
        plt.close(fig)
    # stagnation offset vs eq. (2)
    cs = [out["cases"][n]["c_m"] for n in main_names if out["cases"][n]["s_m"] is not None]
    offs = [out["cases"][n]["offset_m"] for n in main_names if out["cases"][n]["s_m"] is not None]
    if cs:
        fig, ax = plt.subplots(figsize=(4.5, 3.2))
        cc = np.linspace(0, max(cs) * 1.05, 100)
        ax.plot(cc, A1 * cc ** A2, "k-", label="eq. (2): 0.1 |c|^2.33")
        ol = out.get("offset_law")
        if ol:
            ax.plot(cc, ol["A"] * cc ** ol["n"], "C0--", lw=1,
                    label="CFD fit: %.3f |c|^%.2f" % (ol["A"], ol["n"]))
        held = [out["cases"][n].get("held_out") for n in main_names if out["cases"][n]["s_m"] is not None]
        ax.plot([c for c, h in zip(cs, held) if not h], [o for o, h in zip(offs, held) if not h], "o",
                color="C0", label="CFD")
        if any(held):
            ax.plot([c for c, h in zip(cs, held) if h], [o for o, h in zip(offs, held) if h], "s",
                    mfc="none", color="C3", label="CFD, held out")
        ax.set_xlabel("|c| (m)")
        ax.set_ylabel("|c - s| (m)")
        ax.legend(fontsize=8)
        fig.tight_layout()
        fig.savefig(os.path.join(img, "cfd_stagnation.png"), dpi=80)
        plt.close(fig)
    # centreline and wall jet at tilt 0
    n0 = "tilt00.0_mesh1_d20"
    if n0 in cases and "centreline" in cases[n0][2]:
        hdr, _, csv = cases[n0]
        K = hdr["inlet"]["momentum_flux_kinematic_m4_s2"]
        J = math.sqrt(4 * K / math.pi)
        fig, axs = plt.subplots(1, 2, figsize=(8, 3.2))
        cl = csv["centreline"]
        axs[0].plot(cl["s_m"], cl["u_axial_m_s"], label="CFD, tilt 0")
        ss = np.linspace(0.2, H, 50)
        axs[0].plot(ss, 6.0 * J / ss, "k--", label="6 sqrt(4K/pi) / s")
        axs[0].set_ylim(0, 20)
        axs[0].set_xlabel("distance from the exit along the axis (m)")
        axs[0].set_ylabel("centreline speed (m/s)")
        axs[0].legend(fontsize=8)
        w = walljet_fit(hdr, csv)
        axs[1].loglog(w["r"] / H, w["umax"] * H / math.sqrt(K), "o-", ms=3, label="CFD, tilt 0")
        axs[1].loglog(w["r"] / H, 1.32 * (w["r"] / H) ** -1.1, "k--", label="Poreh et al. 1967")
        axs[1].set_xlabel("r / H")
        axs[1].set_ylabel("u_max H / sqrt(K)")
        axs[1].legend(fontsize=8)
        fig.tight_layout()
        fig.savefig(os.path.join(img, "cfd_jet_laws.png"), dpi=80)
        plt.close(fig)


if __name__ == "__main__":
    main()
