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


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--data", default=os.path.join(TOP, "data/cfd"))
    ap.add_argument("--img", default=os.path.join(TOP, "docs/img"))
    ap.add_argument("--json", default=None)
    a = ap.parse_args()
    names = sorted(fn[:-5] for fn in os.listdir(a.data)
                   if fn.endswith(".json") and fn.startswith("tilt"))
    cases = {n: load_case(a.data, n) for n in names}
    if not cases:
        sys.exit("analyse: no cases in %s" % a.data)
    out = {"cases": {}, "independence": {}}
    print("| case | cells | iterations | converged | wall time, mesh + solve (s) | s (m) | abs(c - s) (m) | eq. (2) (m) |"
          " peak at 1.5 cm (m/s) | at (x, y) m |")
    print("|---|---|---|---|---|---|---|---|---|---|")
    for n in names:
        hdr, arr, csv = cases[n]
        c = hdr["projection_point_c_m"][0]
        s = stagnation(hdr, csv)
        sg = stagnation_grid(hdr, arr) if arr is not None else None
        pk = peak(hdr, arr, csv)
        rec = {"tilt_deg": hdr["tilt_deg"], "mesh_level": hdr["mesh_level"],
               "inlet_d_m": hdr["inlet"]["diameter_m"], "cells": hdr["cells"], "iterations": hdr["iterations"],
               "converged": hdr["converged"], "final_residuals": hdr["final_residuals"],
               "wall_time_s": hdr.get("wall_time_s"), "c_m": c, "s_m": s,
               "offset_m": abs(c - s) if s is not None else None, "eq2_offset_m": A1 * abs(c) ** A2,
               "s_grid_min_speed": sg, "peak_z015": pk}
        if "centreline" in csv:
            rec["centreline"] = centreline_fit(hdr, csv)
        out["cases"][n] = rec
        print("| %s | %d | %d | %s | %s | %s | %s | %.3f | %.2f | (%.2f, %.2f) |" % (
            n, hdr["cells"], hdr["iterations"], "yes" if hdr["converged"] else "no",
            "%s + %s" % (rec["wall_time_s"].get("mesh"), rec["wall_time_s"].get("solve")), "%.3f" % s if s is not None else "-",
            "%.3f" % rec["offset_m"] if s is not None else "-", rec["eq2_offset_m"], pk["speed_m_s"],
            pk["x_m"], pk["y_m"]))

    # free jet
    print("\nFree-jet centreline, 1/U_c fitted linear in s (axial speed):")
    for n in names:
        r = out["cases"][n].get("centreline")
        if r:
            print("  %s: B = %.2f, virtual origin %.3f m, fit over s in [%.2f, %.2f] m" % (
                n, r["B"], r["virtual_origin_m"], r["fit_range_m"][0], r["fit_range_m"][1]))

    # wall jet at tilt 0
    wjn = [n for n in names if cases[n][0]["tilt_deg"] == 0.0 and "walljet" in cases[n][2]]
    for n in wjn:
        w = walljet_fit(cases[n][0], cases[n][2])
        out["cases"][n]["walljet"] = {k: v for k, v in w.items() if k not in ("r", "umax", "poreh")}
        print("\nWall jet %s: u_max H/sqrt(K) = %.2f (r/H)^%.2f over r in [%.1f, %.1f] m (Poreh: 1.32 (r/H)^-1.1)"
              % (n, w["coefficient"], w["exponent"], w["fit_range_m"][0], w["fit_range_m"][1]))
        for t in w["table"]:
            print("  r %.2f m: u_max %.2f m/s at z %.1f mm, Poreh %.2f m/s, ratio %.2f" % (
                t["r_m"], t["umax_m_s"], 1000 * t["z_umax_m"], t["poreh_m_s"], t["ratio"]))

    # independence
    print("\nIndependence (in-plane floor speed, MAPE where the reference >= %.1f m/s):" % MASK)
    for n in names:
        hdr, arr, _ = cases[n]
        if hdr["mesh_level"] == 1 and abs(hdr["inlet"]["diameter_m"] - 0.02) < 1e-9:
            continue
        ref = "tilt%04.1f_mesh1_d20" % hdr["tilt_deg"]
        if ref not in cases or arr is None or cases[ref][1] is None:
            continue
        hr, ar, _ = cases[ref]
        if hdr["mesh_level"] == 2:
            what, base, other = "mesh 1 vs mesh 2", arr, ar        # the finer mesh is the reference
        else:
            what, base, other = "inlet 20 mm vs 10 mm", arr, ar    # the smaller inlet is the reference
        res = {}
        for h in (0.0075, 0.015, 0.025):
            res["z%.4f" % h] = mape(inplane(hdr, base, h), inplane(hr, other, h))
        out["independence"][n] = {"what": what, "reference": n, "compared": ref, "by_height": res}
        r15 = res["z0.0150"]
        print("  tilt %g, %s: MAPE %.2f %% (95th percentile %.2f %%, %d points) at 1.5 cm; %.2f %% at 7.5 mm, "
              "%.2f %% at 2.5 cm" % (hdr["tilt_deg"], what, r15["mape_pct"], r15["p95_pct"], r15["points"],
                                    res["z0.0075"]["mape_pct"], res["z0.0250"]["mape_pct"]))

    path = a.json or os.path.join(a.data, "validation.json")
    with open(path, "w") as fh:
        json.dump(out, fh, indent=1, default=float)
        fh.write("\n")
    try:
        import matplotlib
        matplotlib.use("Agg")
        figures(cases, names, out, a.img)
    except ImportError:
        print("(matplotlib missing: no figures; bash scripts/setup.sh --cfd installs it)")


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
        ax.plot(cs, offs, "o", label="CFD")
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
