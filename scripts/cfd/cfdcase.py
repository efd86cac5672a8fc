#!/usr/bin/python3
"""Writes, inspects and converts the OpenFOAM cases of the rig's jet (docs/cfd.md).

Subcommands (all used by run_all.sh):
  list [MODEL]                       the campaign's cases, one per line: name, tilt, mesh level, inlet D;
                                     with a RAS model other than kEpsilon, the turbulence-model study's
                                     cases for that model (MODELS below)
  write    CASE DIR                  case files before meshing: blockMeshDict, rod STL, snappy, schemes
  fields   CASE DIR                  after meshing: inlet area from the mesh, inlet speed, 0/ fields
  progress DIR                       one line: iteration and latest initial residuals of the solver log
  sampledict CASE DIR                system/sampleAll: the floor grid, jet axis, wall-jet profiles
  convert  CASE DIR OUTDIR           samples -> OUTDIR/CASE.json, .f32 and the CSVs
Debian's /usr/bin/python3 with numpy only.
"""
import json
import math
import os
import re
import subprocess
import sys

import numpy as np

# ---------------------------------------------------------------- rig and campaign
H = 1.43                  # nozzle exit height above the floor (m); the tilt pivots about the exit
K_KIN = 1.15              # kinematic momentum flux of the real nozzle (m^4/s^2), docs/cfd.md
NU = 1.5e-5               # air, m^2/s
RHO = 1.2                 # air density used only to quote the momentum flux in N
INTENSITY = 0.05          # inlet turbulence intensity
LSCALE = 0.07             # inlet length scale as a fraction of D
CMU = 0.09
K_AMB = 1e-3              # ambient k and epsilon (small ones diverge with k-epsilon, docs/cfd.md)
EPS_AMB = 1e-3
ROD_LEN = 0.15            # solid rod behind the exit (m)
END_ITER = 2000           # iteration cap; the solver stops earlier on residualControl
RAMP_ITER = 100           # the inlet speed ramps linearly over the first iterations...
RAMP_FROM = 0.1           # ...from this fraction of its value, the inlet k and epsilon with it (as U^2,
                          # U^3): at full inlet k at once, the nozzle lip's cell at 45 deg took k ~ 10
                          # m^2/s^2 while its wall-function epsilon still followed the ambient k, nu_t
                          # reached 1e3 m^2/s and the velocity 9e3 m/s within 3 iterations
RESIDUAL = 1e-4

# shipped floor grid: 1 cm pitch, x in [-1.5, 1.5], y in [0, 1.5] (row 0 at 0.5 mm, off the symmetry plane)
GRID_X0, GRID_NX = -1.5, 301
GRID_Y0, GRID_NY = 0.0, 151
GRID_D = 0.01
Y_ROW0 = 0.0005
HEIGHTS = [0.004, 0.0075, 0.015, 0.025]
FIELDS = ["ux", "uy", "uz", "k", "epsilon", "p"]
UNITS = {"ux": "m/s", "uy": "m/s", "uz": "m/s", "k": "m^2/s^2", "epsilon": "m^2/s^3",
         "p": "m^2/s^2 (kinematic, relative to ambient)"}
WALLJET_DIRS = [0.0, 45.0, 90.0, 135.0, 180.0]

# RAS models of the steady cases: kEpsilon is the campaign's (the paper's COMSOL CFD used it); the
# others are the turbulence-model study (docs/cfd.md, "Sensitivity to the turbulence model"), whose
# cases carry the suffix in their names and whose data go to data/cfd/turbulence/<model>/
DEFAULT_MODEL = "kEpsilon"
MODELS = {"kEpsilon": "", "kOmegaSST": "_sst", "realizableKE": "_rke"}
MODEL_TEXT = {"kEpsilon": "standard k-epsilon",
              "kOmegaSST": "k-omega SST (OpenFOAM's kOmegaSST, Menter et al. 2003)",
              "realizableKE": "realizable k-epsilon (OpenFOAM's realizableKE, Shih et al. 1995)"}
STUDY_TILTS = [22.5, 45.0, 0.0]   # the study's cases in run order, mesh 1, 20 mm inlet
# realizable k-epsilon's lower bound on k (OpenFOAM's default is 1e-15): its epsilon sink,
# eps^2 / (k + sqrt(nu eps)), does not follow k to zero, so in still ambient cells k decayed to the
# default bound while epsilon stayed at 1e-6-1e-5 m^2/s^3; eps/k of ~5e10 then dominated the k
# equation's residual normalisation, k's residual fell to 1e-9, below the solver's tolerance, and k
# froze (0 solver iterations per step) while the residual control counted it converged. 1e-8 is five
# orders below the ambient k
RKE_KMIN = 1e-8


def check_model(model):
    if model not in MODELS:
        sys.exit("cfdcase: unknown RAS model '%s' (expected one of %s)" % (model, ", ".join(MODELS)))
    return model


def campaign(model=DEFAULT_MODEL):
    """Cases in run order: the most useful first. A model other than kEpsilon: the study's cases."""
    check_model(model)
    if model != DEFAULT_MODEL:
        out = []
        for t in STUDY_TILTS:
            base = "tilt%04.1f_mesh%d_d%02d" % (t, 1, 20)
            out.append({"name": base + MODELS[model], "tilt_deg": t, "mesh_level": 1, "inlet_d": 0.020,
                        "held_out": False, "turbulence_model": model, "reference_case": base})
        return out
    cases = []
    for t in [0.0, 22.5, 45.0, 15.0, 30.0, 60.0, 37.5]:
        cases.append((t, 1, 0.020))
    for t in [0.0, 45.0]:
        cases.append((t, 2, 0.020))
    for t in [0.0, 45.0]:
        cases.append((t, 1, 0.010))
    out = []
    for t, lvl, d in cases:
        name = "tilt%04.1f_mesh%d_d%02d" % (t, lvl, round(d * 1000))
        out.append({"name": name, "tilt_deg": t, "mesh_level": lvl, "inlet_d": d,
                    "held_out": t == 37.5})
    return out


def find_case(name):
    for model in MODELS:
        for c in campaign(model):
            if c["name"] == name:
                return c
    sys.exit("cfdcase: unknown case '%s' (see run_all.sh --list)" % name)


def model_of(case):
    return case.get("turbulence_model", DEFAULT_MODEL)


# ---------------------------------------------------------------- geometry
class Geo:
    def __init__(self, case):
        self.case = case
        t = math.radians(case["tilt_deg"])
        self.t = t
        self.d = np.array([math.sin(t), 0.0, -math.cos(t)])   # jet direction
        self.p0 = np.array([0.0, 0.0, H])                        # exit centre
        self.c = H * math.tan(t)                                 # projection point (x)
        self.D = case["inlet_d"]
        self.f = 2.0 ** (1.0 / 3.0) if case["mesh_level"] == 2 else 1.0   # mesh 2: ~2x cells
        # domain
        self.x0 = -2.0
        self.x1 = max(2.0, self.c + 2.0)
        self.y1 = 2.0
        self.z1 = 2.0
        # refinement level of the inlet: ~10 cells across D on the 3 cm background
        self.ls = int(math.ceil(math.log2(0.03 / self.f * 10.0 / self.D) - 1e-9))


def seg_cells(length, h0, h1):
    """Cells of a geometric segment from size h0 to h1 over length."""
    if abs(h1 - h0) < 1e-12:
        return max(1, int(round(length / h0)))
    mean = (h1 - h0) / math.log(h1 / h0)
    return max(1, int(round(length / mean)))


def grading(segs):
    """segs: list of (length, h_start, h_end) -> (n total, blockMesh multi-grading string)."""
    parts, n = [], 0
    for length, a, b in segs:
        m = seg_cells(length, a, b)
        n += m
        parts.append("(%.6g %d %.6g)" % (length, m, b / a))
    return n, "(" + " ".join(parts) + ")"


def write_file(path, cls, obj, body, location=None):
    os.makedirs(os.path.dirname(path), exist_ok=True)
    loc = '    location    "%s";\n' % location if location else ""
    with open(path, "w") as fh:
        fh.write("FoamFile\n{\n    version     2.0;\n    format      ascii;\n"
                 "    class       %s;\n%s    object      %s;\n}\n\n" % (cls, loc, obj))
        fh.write(body)


def v3(p):
    return "(%.9g %.9g %.9g)" % tuple(p)


def block_mesh(g):
    f = g.f
    fine, coarse = 0.03 / f, 0.08 / f
    xa, xb = -1.0, max(1.0, g.c + 1.0)
    nx, gx = grading([(xa - g.x0, coarse, fine), (xb - xa, fine, fine), (g.x1 - xb, fine, coarse)])
    ny, gy = grading([(1.0, fine, fine), (g.y1 - 1.0, fine, coarse)])
    first, mid, top = 0.004 / f, 0.03 / f, 0.06 / f
    nz, gz = grading([(0.25, first, mid), (0.65, mid, top), (g.z1 - 0.9, top, top)])
    x0, x1, y1, z1 = g.x0, g.x1, g.y1, g.z1
    verts = [(x0, 0, 0), (x1, 0, 0), (x1, y1, 0), (x0, y1, 0),
             (x0, 0, z1), (x1, 0, z1), (x1, y1, z1), (x0, y1, z1)]
    body = "convertToMeters 1;\n\nvertices\n(\n"
    body += "".join("    %s\n" % v3(v) for v in verts)
    body += ");\n\nblocks\n(\n    hex (0 1 2 3 4 5 6 7) (%d %d %d)\n    simpleGrading\n    (\n" % (nx, ny, nz)
    body += "        %s\n        %s\n        %s\n    )\n);\n\nedges ();\n\n" % (gx, gy, gz)
    body += """boundary
(
    floor
    {
        type wall;
        faces ((0 3 2 1));
    }
    symmetry
    {
        type symmetry;
        faces ((0 1 5 4));
    }
    atmosphere
    {
        type patch;
        faces ((0 4 7 3) (1 2 6 5) (3 7 6 2) (4 5 6 7));
    }
);

mergePatchPairs ();
"""
    return body, nx * ny * nz


def rod_stl(g, n=96):
    """Closed solid rod of diameter D on the jet axis, from the exit back ROD_LEN; solid 'inlet' is
    the exit cap (normal along the jet), solid 'wall' the side and the back cap (normals outward)."""
    d = g.d
    e1 = np.array([0.0, 1.0, 0.0])
    e2 = np.cross(d, e1)
    r = g.D / 2.0
    a = g.p0
    b = g.p0 - ROD_LEN * d
    ang = [2 * math.pi * i / n for i in range(n)]
    ring = [r * (math.cos(q) * e1 + math.sin(q) * e2) for q in ang]

    def tri(p, q, s, want):
        nrm = np.cross(q - p, s - p)
        if np.dot(nrm, want) < 0:
            q, s = s, q
            nrm = -nrm
        nrm = nrm / np.linalg.norm(nrm)
        return "  facet normal %s\n    outer loop\n      vertex %s\n      vertex %s\n      vertex %s\n" \
               "    endloop\n  endfacet\n" % tuple(
                   " ".join("%.9g" % x for x in v) for v in (nrm, p, q, s))

    out = ["solid inlet\n"]
    for i in range(n):
        j = (i + 1) % n
        out.append(tri(a, a + ring[i], a + ring[j], d))
    out.append("endsolid inlet\nsolid wall\n")
    for i in range(n):
        j = (i + 1) % n
        mid = 0.5 * (ring[i] + ring[j])
        out.append(tri(a + ring[i], b + ring[i], b + ring[j], mid))
        out.append(tri(a + ring[i], b + ring[j], a + ring[j], mid))
        out.append(tri(b, b + ring[j], b + ring[i], -d))
    out.append("endsolid wall\n")
    return "".join(out)


def shells(g):
    """Refinement cylinders along the jet axis: (level, radius, start behind exit, end ahead of exit)."""
    t = g.t
    # the level-1 cylinder stops 0.3 m above the floor everywhere, so floor cells are never split
    r1 = 0.25
    z_end = 0.3 + r1 * math.sin(t)
    len1 = (H - z_end) / math.cos(t)
    sh = [(1, r1, 0.20, len1), (2, 0.10, 0.18, 0.60), (3, 0.05, 0.10, 0.25), (4, 0.03, 0.04, 0.12)]
    if g.ls >= 5:
        sh.append((5, 0.015, 0.02, 0.06))
    return [s for s in sh if s[0] <= g.ls]


def snappy_dict(g):
    geo = "    rod.stl\n    {\n        type triSurfaceMesh;\n        name rod;\n    }\n"
    regions = ""
    for lvl, rad, back, ahead in shells(g):
        p1 = g.p0 - back * g.d
        p2 = g.p0 + ahead * g.d
        geo += "    shell%d\n    {\n        type searchableCylinder;\n        point1 %s;\n" \
               "        point2 %s;\n        radius %.6g;\n    }\n" % (lvl, v3(p1), v3(p2), rad)
        regions += "        shell%d { mode inside; levels ((1e15 %d)); }\n" % (lvl, lvl)
    ls = g.ls
    loc = (-1.2345, 0.7123, 0.5432)
    return """castellatedMesh true;
snap            true;
addLayers       false;

geometry
{
%s}

castellatedMeshControls
{
    maxLocalCells 3000000;
    maxGlobalCells 8000000;
    minRefinementCells 0;
    maxLoadUnbalance 0.10;
    nCellsBetweenLevels 3;
    features
    (
        { file "rod.eMesh"; level %d; }
    );
    refinementSurfaces
    {
        rod
        {
            level (%d %d);
            regions
            {
                inlet { level (%d %d); patchInfo { type patch; } }
                wall  { level (%d %d); patchInfo { type wall; } }
            }
        }
    }
    resolveFeatureAngle 30;
    refinementRegions
    {
%s    }
    locationInMesh %s;
    allowFreeStandingZoneFaces true;
}

snapControls
{
    nSmoothPatch 3;
    tolerance 2.0;
    nSolveIter 50;
    nRelaxIter 5;
    nFeatureSnapIter 10;
    implicitFeatureSnap false;
    explicitFeatureSnap true;
    multiRegionFeatureSnap true;
}

addLayersControls
{
    relativeSizes true;
    layers {}
    expansionRatio 1.0;
    finalLayerThickness 0.3;
    minThickness 0.1;
    nGrow 0;
    featureAngle 60;
    nRelaxIter 3;
    nSmoothSurfaceNormals 1;
    nSmoothNormals 3;
    nSmoothThickness 10;
    maxFaceThicknessRatio 0.5;
    maxThicknessToMedialRatio 0.3;
    minMedialAxisAngle 90;
    nBufferCellsNoExtrude 0;
    nLayerIter 50;
}

meshQualityControls
{
    maxNonOrtho 65;
    maxBoundarySkewness 20;
    maxInternalSkewness 4;
    maxConcave 80;
    minVol 1e-13;
    minTetQuality 1e-15;
    minArea -1;
    minTwist 0.02;
    minDeterminant 0.001;
    minFaceWeight 0.05;
    minVolRatio 0.01;
    minTriangleTwist -1;
    nSmoothScale 4;
    errorReduction 0.75;
    relaxed { maxNonOrtho 75; }
}

mergeTolerance 1e-6;
""" % (geo, ls, ls - 1, ls - 1, ls, ls, ls - 1, ls - 1, regions, v3(loc))


CONTROL = """application     simpleFoam;
startFrom       latestTime;
startTime       0;
stopAt          endTime;
endTime         %d;
deltaT          1;
writeControl    timeStep;
writeInterval   %d;
purgeWrite      0;
writeFormat     ascii;
writePrecision  8;
writeCompression off;
timeFormat      general;
timePrecision   6;
runTimeModifiable false;
"""

SCHEMES = """ddtSchemes { default steadyState; }

gradSchemes
{
    default         Gauss linear;
    grad(U)         cellLimited Gauss linear 1;
}

divSchemes
{
    default         none;
    div(phi,U)      bounded Gauss linearUpwind grad(U);
    div(phi,k)      bounded Gauss upwind;
    div(phi,epsilon) bounded Gauss upwind;
    div((nuEff*dev2(T(grad(U))))) Gauss linear;
}

laplacianSchemes { default Gauss linear limited corrected 0.5; }
interpolationSchemes { default linear; }
snGradSchemes { default limited corrected 0.5; }
wallDist { method meshWave; }
"""

SOLUTION = """solvers
{
    p
    {
        solver          GAMG;
        smoother        GaussSeidel;
        tolerance       1e-7;
        relTol          0.05;
    }
    "(U|k|epsilon)"
    {
        solver          smoothSolver;
        smoother        symGaussSeidel;
        tolerance       1e-8;
        relTol          0.1;
    }
}

SIMPLE
{
    consistent      yes;
    nNonOrthogonalCorrectors 0;
    residualControl
    {
        p               %g;
        U               %g;
        "(k|epsilon)"   %g;
    }
}

relaxationFactors
{
    equations
    {
        U               0.8;
        "(k|epsilon)"   0.7;
    }
}
""" % (RESIDUAL, RESIDUAL, RESIDUAL)


def write_feature_dict(case_dir):
    """surfaceFeatureExtract's dictionary for the rod's edges."""
    write_file(os.path.join(case_dir, "system/surfaceFeatureExtractDict"), "dictionary",
               "surfaceFeatureExtractDict", """rod.stl
{
    extractionMethod extractFromSurface;
    extractFromSurfaceCoeffs { includedAngle 150; }
    subsetFeatures { nonManifoldEdges no; openEdges yes; }
    writeObj no;
}
""")


def schemes(model):
    """fvSchemes: the campaign's, with omega's convection for k-omega SST."""
    if model == "kOmegaSST":
        return SCHEMES.replace("    div(phi,epsilon) bounded Gauss upwind;\n",
                               "    div(phi,omega)  bounded Gauss upwind;\n")
    return SCHEMES


def solution(model):
    """fvSolution: the campaign's; k-omega SST solves, relaxes and checks omega as k-epsilon does
    epsilon (the same solver, relaxation 0.7 and residual target)."""
    if model == "kOmegaSST":
        return SOLUTION.replace("(U|k|epsilon)", "(U|k|omega)").replace('"(k|epsilon)"', '"(k|omega)"')
    return SOLUTION


def write_common(case_dir, model=DEFAULT_MODEL):
    """The decomposition over 2 ranks, air's viscosity and the RAS model (standard k-epsilon)."""
    write_file(os.path.join(case_dir, "system/decomposeParDict"), "dictionary", "decomposeParDict",
               "numberOfSubdomains 2;\nmethod hierarchical;\ncoeffs { n (2 1 1); order xyz; }\n"
               "hierarchicalCoeffs { n (2 1 1); delta 0.001; order xyz; }\n")
    write_file(os.path.join(case_dir, "constant/transportProperties"), "dictionary",
               "transportProperties", "transportModel Newtonian;\nnu [0 2 -1 0 0 0 0] %g;\n" % NU)
    write_file(os.path.join(case_dir, "constant/turbulenceProperties"), "dictionary",
               "turbulenceProperties",
               "simulationType RAS;\nRAS\n{\n    RASModel %s;\n    turbulence on;\n"
               "    printCoeffs on;\n%s}\n" % (check_model(model),
                                             "    kMin %g;\n" % RKE_KMIN if model == "realizableKE" else ""))


def cmd_write(name, case_dir):
    case = find_case(name)
    g = Geo(case)
    bm, nbg = block_mesh(g)
    write_file(os.path.join(case_dir, "system/blockMeshDict"), "dictionary", "blockMeshDict", bm)
    write_file(os.path.join(case_dir, "system/snappyHexMeshDict"), "dictionary", "snappyHexMeshDict",
               snappy_dict(g))
    write_feature_dict(case_dir)
    write_file(os.path.join(case_dir, "system/controlDict"), "dictionary", "controlDict",
               CONTROL % (END_ITER, 100))
    write_file(os.path.join(case_dir, "system/fvSchemes"), "dictionary", "fvSchemes", schemes(model_of(case)))
    write_file(os.path.join(case_dir, "system/fvSolution"), "dictionary", "fvSolution",
               solution(model_of(case)))
    write_common(case_dir, model_of(case))
    os.makedirs(os.path.join(case_dir, "constant/triSurface"), exist_ok=True)
    with open(os.path.join(case_dir, "constant/triSurface/rod.stl"), "w") as fh:
        fh.write(rod_stl(g))
    meta = {"case": case, "generator_commit": git_commit_of(os.path.dirname(os.path.abspath(__file__))),
            "background_cells": nbg, "inlet_refinement_level": g.ls,
            "domain_m": {"x": [g.x0, g.x1], "y": [0.0, g.y1], "z": [0.0, g.z1]},
            "shells": [{"level": s[0], "radius_m": s[1], "behind_exit_m": s[2], "ahead_of_exit_m": s[3]}
                       for s in shells(g)]}
    with open(os.path.join(case_dir, "case.json"), "w") as fh:
        json.dump(meta, fh, indent=1)


# ---------------------------------------------------------------- mesh reading (ascii polyMesh)
def _strip_header(txt):
    i = txt.find("FoamFile")
    if i >= 0:
        j = txt.find("}", i)
        txt = txt[j + 1:]
    return re.sub(r"//[^\n]*", "", txt)


def read_boundary(mesh_dir):
    txt = _strip_header(open(os.path.join(mesh_dir, "boundary")).read())
    out = {}
    for m in re.finditer(r"(\w+)\s*\{([^}]*)\}", txt):
        body = m.group(2)
        nf = re.search(r"nFaces\s+(\d+)", body)
        sf = re.search(r"startFace\s+(\d+)", body)
        ty = re.search(r"\btype\s+(\w+)", body)
        if nf and sf:
            out[m.group(1)] = {"type": ty.group(1), "nFaces": int(nf.group(1)), "startFace": int(sf.group(1))}
    return out


def _list_body(path):
    txt = _strip_header(open(path).read())
    i = txt.find("(")
    n = int(txt[:i].split()[-1])
    return n, txt[i + 1:txt.rfind(")")]


def patch_area(mesh_dir, patch):
    """Vector and scalar area of a patch from the ascii points and faces."""
    b = read_boundary(mesh_dir)[patch]
    n, body = _list_body(os.path.join(mesh_dir, "points"))
    pts = np.array(body.replace("(", " ").replace(")", " ").split(), dtype=float).reshape(n, 3)
    _, fbody = _list_body(os.path.join(mesh_dir, "faces"))
    faces = re.findall(r"\d+\(([\d ]+)\)", fbody)
    vec = np.zeros(3)
    mag = 0.0
    for fi in range(b["startFace"], b["startFace"] + b["nFaces"]):
        idx = [int(v) for v in faces[fi].split()]
        p = pts[idx]
        ctr = p.mean(axis=0)
        a = np.zeros(3)
        for k in range(len(idx)):
            a += 0.5 * np.cross(p[k] - ctr, p[(k + 1) % len(idx)] - ctr)
        vec += a
        mag += np.linalg.norm(a)
    return vec, mag, b["nFaces"]


def count_cells(mesh_dir):
    txt = open(os.path.join(mesh_dir, "owner")).read(4000)
    m = re.search(r"nCells:\s*(\d+)", txt)
    return int(m.group(1)) if m else None


def ramp_table(value):
    """Function1 table entries over the inlet ramp: value(f) at f = RAMP_FROM .. 1, 11 points."""
    n = 10
    return " ".join("(%d %s)" % (round(RAMP_ITER * i / n), value(RAMP_FROM + (1.0 - RAMP_FROM) * i / n))
                    for i in range(n + 1))


SYMMETRY = "    symmetry\n    {\n        type symmetry;\n    }\n"


def write_fields(zero, inlet, side, u_table, u0, k_table, k0, eps_table, eps0):
    """The 0/ fields of a jet case: the inlet patch `inlet` following Function1 tables (over
    iterations or seconds; u0, k0, eps0 their values at the start, as text), the floor and the
    rod no-slip with wall functions, the atmosphere open (total pressure, inflow of ambient
    turbulence), and `side`, the boundary entry of the symmetry or wedge patches."""
    walls = "    \"(floor|rod_wall)\"\n    {\n        type %s;\n%s    }\n"
    write_file(os.path.join(zero, "U"), "volVectorField", "U",
               "dimensions [0 1 -1 0 0 0 0];\n\ninternalField uniform (0 0 0);\n\nboundaryField\n{\n"
               "    %s\n    {\n        type uniformFixedValue;\n        uniformValue table (%s);\n"
               "        value uniform %s;\n    }\n" % (inlet, u_table, u0)
               + walls % ("noSlip", "") + side +
               "    atmosphere\n    {\n        type pressureInletOutletVelocity;\n"
               "        value uniform (0 0 0);\n    }\n}\n")
    write_file(os.path.join(zero, "p"), "volScalarField", "p",
               "dimensions [0 2 -2 0 0 0 0];\n\ninternalField uniform 0;\n\nboundaryField\n{\n"
               "    \"(%s|rod_wall|floor)\"\n    {\n        type zeroGradient;\n    }\n" % inlet + side +
               "    atmosphere\n    {\n        type totalPressure;\n        p0 uniform 0;\n"
               "        value uniform 0;\n    }\n}\n")
    for fld, dims, table, v0, amb, wf in (("k", "[0 2 -2 0 0 0 0]", k_table, k0, K_AMB, "kqRWallFunction"),
                                          ("epsilon", "[0 2 -3 0 0 0 0]", eps_table, eps0, EPS_AMB,
                                           "epsilonWallFunction")):
        write_file(os.path.join(zero, fld), "volScalarField", fld,
                   "dimensions %s;\n\ninternalField uniform %g;\n\nboundaryField\n{\n"
                   "    %s\n    {\n        type uniformFixedValue;\n        uniformValue table (%s);\n"
                   "        value uniform %s;\n    }\n" % (dims, amb, inlet, table, v0)
                   + walls % (wf, "        value uniform %g;\n" % amb) + side +
                   "    atmosphere\n    {\n        type inletOutlet;\n        inletValue uniform %g;\n"
                   "        value uniform %g;\n    }\n}\n" % (amb, amb))
    write_file(os.path.join(zero, "nut"), "volScalarField", "nut",
               "dimensions [0 2 -1 0 0 0 0];\n\ninternalField uniform 0;\n\nboundaryField\n{\n"
               "    \"(%s|atmosphere)\"\n    {\n        type calculated;\n        value uniform 0;\n    }\n"
               % inlet + walls % ("nutkWallFunction", "        value uniform 0;\n") + side + "}\n")


def write_omega(zero, inlet, side, table, v0, amb):
    """k-omega SST's 0/omega in place of 0/epsilon: the inlet following its table, omega wall functions
    on the floor and the rod, the ambient omega flowing in at the atmosphere."""
    walls = "    \"(floor|rod_wall)\"\n    {\n        type omegaWallFunction;\n        value uniform %g;\n    }\n"
    write_file(os.path.join(zero, "omega"), "volScalarField", "omega",
               "dimensions [0 0 -1 0 0 0 0];\n\ninternalField uniform %g;\n\nboundaryField\n{\n"
               "    %s\n    {\n        type uniformFixedValue;\n        uniformValue table (%s);\n"
               "        value uniform %s;\n    }\n" % (amb, inlet, table, v0)
               + walls % amb + side +
               "    atmosphere\n    {\n        type inletOutlet;\n        inletValue uniform %g;\n"
               "        value uniform %g;\n    }\n}\n" % (amb, amb))
    eps = os.path.join(zero, "epsilon")
    if os.path.exists(eps):
        os.remove(eps)


def omega_of(k, eps):
    """The specific dissipation rate of k and epsilon: omega = epsilon / (C_mu k)."""
    return eps / (CMU * k)


def cmd_fields(name, case_dir):
    case = find_case(name)
    g = Geo(case)
    mesh = os.path.join(case_dir, "constant/polyMesh")
    bnd = read_boundary(mesh)
    for need in ("rod_inlet", "rod_wall", "floor", "symmetry", "atmosphere"):
        if need not in bnd:
            sys.exit("cfdcase: patch %s missing after meshing (have %s)" % (need, sorted(bnd)))
    vec, mag, nfaces = patch_area(mesh, "rod_inlet")
    # half domain: the inlet patch is half the disc and carries half the momentum flux
    a_nom = math.pi * g.D ** 2 / 8.0
    a_eff = abs(float(np.dot(vec, g.d)))
    u = math.sqrt(0.5 * K_KIN / a_eff)
    k_in = 1.5 * (INTENSITY * u) ** 2
    eps_in = CMU ** 0.75 * k_in ** 1.5 / (LSCALE * g.D)
    uvec = u * g.d
    write_fields(os.path.join(case_dir, "0"), "rod_inlet", SYMMETRY,
                 ramp_table(lambda f: v3(f * uvec)), v3(RAMP_FROM * uvec),
                 ramp_table(lambda f: "%.9g" % (k_in * f ** 2)), "%.9g" % (k_in * RAMP_FROM ** 2),
                 ramp_table(lambda f: "%.9g" % (eps_in * f ** 3)), "%.9g" % (eps_in * RAMP_FROM ** 3))
    model = model_of(case)
    if model == "kOmegaSST":
        # inlet omega from k and the length scale, ambient omega from the ambient k and epsilon; along
        # the ramp omega = sqrt(k) / (C_mu^0.25 l) follows U as k does U^2
        om_in = omega_of(k_in, eps_in)
        write_omega(os.path.join(case_dir, "0"), "rod_inlet", SYMMETRY,
                    ramp_table(lambda f: "%.9g" % (om_in * f)), "%.9g" % (om_in * RAMP_FROM),
                    omega_of(K_AMB, EPS_AMB))
    info = {"cells": count_cells(mesh), "inlet_faces": nfaces, "inlet_area_m2": a_eff,
            "inlet_area_nominal_m2": a_nom, "inlet_area_error_pct": 100.0 * (a_eff / a_nom - 1.0),
            "inlet_speed_m_s": u, "k_inlet": k_in, "epsilon_inlet": eps_in,
            "ramp": {"iterations": RAMP_ITER, "from_fraction": RAMP_FROM},
            "generator_commit": git_commit_of(os.path.dirname(os.path.abspath(__file__))),
            "momentum_flux_kinematic_m4_s2": 2.0 * u * u * a_eff}
    if model != DEFAULT_MODEL:
        info["turbulence_model"] = model
    if model == "kOmegaSST":
        info["omega_inlet"] = omega_of(k_in, eps_in)
    with open(os.path.join(case_dir, "inlet.json"), "w") as fh:
        json.dump(info, fh, indent=1)
    print("cells %d, inlet %d faces, area %.4g m^2 (%.2f %% off nominal), U %.2f m/s" %
          (info["cells"] or -1, nfaces, a_eff, info["inlet_area_error_pct"], u))


# ---------------------------------------------------------------- solver log
RES_RE = re.compile(r"Solving for (\w+), Initial residual = ([0-9.eE+-]+)")


def parse_log(path, clock=None):
    """-> (last iteration, {field: last initial residual}, converged iteration or None, version)"""
    it, res, conv, version = 0, {}, None, None
    if not os.path.exists(path):
        return it, res, conv, version
    cur = {}
    with open(path, errors="replace") as fh:
        for line in fh:
            if line.startswith("Time = "):
                try:
                    it = int(float(line.split()[2]))
                except ValueError:
                    pass
                if cur:
                    res = cur
                cur = {}
            elif "Solving for" in line:
                m = RES_RE.search(line)
                if m and m.group(1) not in cur:
                    cur[m.group(1)] = float(m.group(2))
            elif clock is not None and line.startswith("ExecutionTime"):
                m = re.search(r"ClockTime = ([0-9.]+)", line)
                if m:
                    clock.append((it, float(m.group(1))))
            elif "SIMPLE solution converged in" in line:
                conv = int(line.split("converged in")[1].split()[0])
            elif version is None and line.startswith("Build") and ":" in line:
                version = line.split(":", 1)[1].strip()     # e.g. "OPENFOAM=1912 patch=200626"
    if cur and ("k" in cur or not res):   # the last iteration, if complete
        res = cur
    return it, res, conv, version


def cmd_progress(case_dir):
    clock = []
    it, res, conv, _ = parse_log(os.path.join(case_dir, "log.simpleFoam"), clock)
    parts = ["iteration %d" % it]
    for f in ("p", "Ux", "Uz", "k", "epsilon", "omega"):
        if f in res:
            parts.append("residual %s %.1e" % (f, res[f]))
    if conv:
        parts.append("converged")
    if len(clock) > 20:
        (i0, c0), (i1, c1) = clock[-21], clock[-1]
        if i1 > i0:
            parts.append("%.2f s/iteration" % ((c1 - c0) / (i1 - i0)))
    try:
        parts.append("load %s" % open("/proc/loadavg").read().split()[0])
    except OSError:
        pass
    print(", ".join(parts))


# ---------------------------------------------------------------- sampling
def grid_x():
    return GRID_X0 + GRID_D * np.arange(GRID_NX)


def grid_y():
    y = GRID_Y0 + GRID_D * np.arange(GRID_NY)
    y[0] = Y_ROW0
    return y


def centre_points(g):
    L = H / math.cos(g.t) - 0.002
    s = np.arange(0.005, L, 0.005)
    pts = g.p0[None, :] + s[:, None] * g.d[None, :]
    pts[:, 1] = Y_ROW0
    return s, pts


def axis_points(g):
    x = np.arange(g.x0 + 0.005, g.x1 - 0.004, 0.005)
    return np.stack([x, np.full_like(x, Y_ROW0), np.full_like(x, 0.015)], axis=1)


WJ_Z = np.concatenate([np.arange(0.001, 0.0201, 0.001), np.arange(0.0225, 0.0601, 0.0025),
                       np.arange(0.065, 0.1501, 0.005)])
WJ_R = np.arange(0.05, 1.5001, 0.025)


def walljet_points(g):
    pts = []
    for a in WALLJET_DIRS:
        ca, sa = math.cos(math.radians(a)), math.sin(math.radians(a))
        for r in WJ_R:
            x, y = g.c + r * ca, max(r * sa, Y_ROW0)
            for z in WJ_Z:
                pts.append((x, y, z))
    return np.array(pts)


def cloud(name, pts):
    s = "    %s\n    {\n        type cloud;\n        axis xyz;\n        points\n        (\n" % name
    s += "".join("            (%.6f %.6f %.6f)\n" % tuple(p) for p in pts)
    return s + "        );\n    }\n"


def cmd_sampledict(name, case_dir):
    case = find_case(name)
    g = Geo(case)
    xx, yy = np.meshgrid(grid_x(), grid_y())
    body = ("type sets;\nlibs (\"libsampling.so\");\nwriteControl writeTime;\n"
            "interpolationScheme cellPoint;\nsetFormat raw;\nfields (U p k %s);\n\nsets\n(\n"
            % ("omega" if model_of(case) == "kOmegaSST" else "epsilon"))
    for i, h in enumerate(HEIGHTS):
        pts = np.stack([xx.ravel(), yy.ravel(), np.full(xx.size, h)], axis=1)
        body += cloud("h%d" % i, pts)
    body += cloud("centre", centre_points(g)[1])
    body += cloud("axis", axis_points(g))
    body += cloud("walljet", walljet_points(g))
    body += ");\n"
    write_file(os.path.join(case_dir, "system/sampleAll"), "dictionary", "sampleAll", body)


def read_set(folder, setname):
    """-> (points (n,3), {field: values}) merging the vector and scalar files of one set."""
    data, pts = {}, None
    for fn in sorted(os.listdir(folder)):
        if not fn.startswith(setname + "_") or not fn.endswith(".xy"):
            continue
        names = fn[len(setname) + 1:-3].split("_")
        arr = np.loadtxt(os.path.join(folder, fn), ndmin=2)
        if pts is None:
            pts = arr[:, :3]
        elif len(arr) != len(pts) or np.abs(arr[:, :3] - pts).max() > 1e-6:
            sys.exit("cfdcase: sample files of set %s disagree" % setname)
        col = 3
        for nm in names:
            if nm == "U":
                data["ux"], data["uy"], data["uz"] = arr[:, col], arr[:, col + 1], arr[:, col + 2]
                col += 3
            else:
                data[nm] = arr[:, col]
                col += 1
    if pts is None:
        sys.exit("cfdcase: no samples for set %s in %s" % (setname, folder))
    if "omega" in data and "epsilon" not in data:   # k-omega SST: epsilon = C_mu k omega (beta* = C_mu)
        data["epsilon"] = CMU * data["k"] * data["omega"]
    return pts, data


def git_commit_of(path, gen=("scripts/cfd/cfdcase.py", "scripts/cfd/run_all.sh")):
    """The last commit of the generator's files (default: the steady campaign's case writer and
    runner, not the analysis or benchmark scripts), "-modified" if they differ from it."""
    try:
        top = subprocess.run(["git", "-C", path, "rev-parse", "--show-toplevel"], capture_output=True,
                             text=True, check=True).stdout.strip()
        h = subprocess.run(["git", "-C", top, "log", "-1", "--format=%H", "--"] + list(gen),
                           capture_output=True, text=True, check=True).stdout.strip()
        dirty = subprocess.run(["git", "-C", top, "status", "--porcelain", "--untracked-files=no", "--"]
                               + list(gen),
                               capture_output=True, text=True, check=True).stdout.strip()
        return h + ("-modified" if dirty else "") if h else "uncommitted"
    except (subprocess.CalledProcessError, FileNotFoundError):
        return "unknown"


def cmd_convert(name, case_dir, out_dir):
    case = find_case(name)
    g = Geo(case)
    pp = os.path.join(case_dir, "postProcessing/sampleAll")
    times = sorted(os.listdir(pp), key=float)
    folder = os.path.join(pp, times[-1])
    os.makedirs(out_dir, exist_ok=True)
    xg, yg = grid_x(), grid_y()
    arr = np.full((len(HEIGHTS), len(FIELDS), GRID_NY, GRID_NX), np.nan, dtype=np.float64)
    for hi in range(len(HEIGHTS)):
        pts, d = read_set(folder, "h%d" % hi)
        ix = np.rint((pts[:, 0] - GRID_X0) / GRID_D).astype(int)
        iy = np.rint((pts[:, 1] - GRID_Y0) / GRID_D).astype(int)
        for fi, f in enumerate(FIELDS):
            arr[hi, fi, iy, ix] = d[f]
    missing = int(np.isnan(arr[:, 0]).sum())
    if missing:
        print("cfdcase: warning: %d grid points not found in the mesh, NaN in the data" % missing)
    arr.astype("<f4").tofile(os.path.join(out_dir, name + ".f32"))

    # jet centreline
    s_all, _ = centre_points(g)
    pts, d = read_set(folder, "centre")
    s = (pts - g.p0[None, :]) @ g.d
    spd = np.sqrt(d["ux"] ** 2 + d["uy"] ** 2 + d["uz"] ** 2)
    ua = d["ux"] * g.d[0] + d["uy"] * g.d[1] + d["uz"] * g.d[2]
    with open(os.path.join(out_dir, name + "_centreline.csv"), "w") as fh:
        fh.write("s_m,x_m,z_m,speed_m_s,u_axial_m_s,k_m2_s2\n")
        for i in range(0, len(s), 2):   # 1 cm pitch in the shipped file
            fh.write("%.3f,%.4f,%.4f,%.4f,%.4f,%.5f\n" % (s[i], pts[i, 0], pts[i, 2], spd[i], ua[i], d["k"][i]))

    # symmetry line of the floor at 1.5 cm: the stagnation point
    pts, d = read_set(folder, "axis")
    with open(os.path.join(out_dir, name + "_axisline.csv"), "w") as fh:
        fh.write("x_m,ux_m_s,uz_m_s,p_m2_s2\n")
        for i in range(len(pts)):
            fh.write("%.3f,%.4f,%.4f,%.5f\n" % (pts[i, 0], d["ux"][i], d["uz"][i], d["p"][i]))
    s_x = stagnation_from_line(pts[:, 0], d["ux"], g.c)

    # wall jet: maximum in-plane speed over height along directions from c
    pts, d = read_set(folder, "walljet")
    sp = np.sqrt(d["ux"] ** 2 + d["uy"] ** 2)
    rows = []
    for a in WALLJET_DIRS:
        ca, sa = math.cos(math.radians(a)), math.sin(math.radians(a))
        for r in WJ_R:
            x, y = g.c + r * ca, max(r * sa, Y_ROW0)
            sel = (np.abs(pts[:, 0] - x) < 1e-5) & (np.abs(pts[:, 1] - y) < 1e-5)
            if not sel.any():
                continue
            zz, uu = pts[sel, 2], sp[sel]
            j = int(np.argmax(uu))
            u15 = float(np.interp(0.015, zz, uu))
            rows.append((a, r, uu[j], zz[j], u15))
    with open(os.path.join(out_dir, name + "_walljet.csv"), "w") as fh:
        fh.write("direction_deg,r_from_c_m,umax_m_s,z_umax_m,u_z015_m_s\n")
        for row in rows:
            fh.write("%.1f,%.3f,%.4f,%.4f,%.4f\n" % row)

    # header
    meta = json.load(open(os.path.join(case_dir, "case.json")))
    inlet = json.load(open(os.path.join(case_dir, "inlet.json")))
    run = json.load(open(os.path.join(case_dir, "run.json"))) if os.path.exists(
        os.path.join(case_dir, "run.json")) else {}
    it, res, conv, version = parse_log(os.path.join(case_dir, "log.simpleFoam"))
    if run.get("mesh_time_s") is None:
        run["mesh_time_s"] = mesh_clock(case_dir)
    hi15 = HEIGHTS.index(0.015)
    spd15 = np.hypot(arr[hi15, 0], arr[hi15, 1])
    k = int(np.nanargmax(spd15))
    hdr = {
        "format": "airtwin-cfd-floor 1",
        "case": name,
        "tilt_deg": case["tilt_deg"],
        "held_out": case["held_out"],
        "mesh_level": case["mesh_level"],
        "cells": inlet["cells"],
        "nozzle_exit_m": [0.0, 0.0, H],
        "jet_direction": [round(v, 9) for v in g.d.tolist()],
        "projection_point_c_m": [g.c, 0.0],
        "stagnation_point_s_m": [s_x, 0.0] if s_x is not None else None,
        "inlet": {"diameter_m": g.D, "half_area_m2": inlet["inlet_area_m2"],
                  "half_area_nominal_m2": inlet["inlet_area_nominal_m2"], "speed_m_s": inlet["inlet_speed_m_s"],
                  "momentum_flux_kinematic_m4_s2": inlet["momentum_flux_kinematic_m4_s2"],
                  "momentum_flux_N_at_rho_1_2": RHO * inlet["momentum_flux_kinematic_m4_s2"],
                  "k_m2_s2": inlet["k_inlet"], "epsilon_m2_s3": inlet["epsilon_inlet"],
                  "turbulence_intensity": INTENSITY, "length_scale_m": LSCALE * g.D,
                  "speed_ramp": inlet.get("ramp")},
        "ambient": {"k_m2_s2": K_AMB, "epsilon_m2_s3": EPS_AMB, "nu_m2_s": NU},
        "model": "steady RANS, %s, simpleFoam (SIMPLEC)" % MODEL_TEXT[model_of(case)],
        "iterations": it,
        "converged": conv is not None,
        "residual_target": RESIDUAL,
        "final_residuals": res,
        "openfoam_version": version,
        "generator_commit": inlet.get("generator_commit", meta.get("generator_commit")),
        "mesh_generator_commit": meta.get("generator_commit"),
        "domain_m": meta["domain_m"],
        "wall_time_s": {"mesh": run.get("mesh_time_s"), "solve": run.get("wall_time_s"),
                        "note": "elapsed, on a shared 2-core machine under nice 19"},
        "mpi_ranks": run.get("ranks"),
        "grid": {"x0_m": GRID_X0, "dx_m": GRID_D, "nx": GRID_NX, "y0_m": GRID_Y0, "dy_m": GRID_D, "ny": GRID_NY,
                 "row_iy0_sampled_at_y_m": Y_ROW0, "heights_m": HEIGHTS,
                 "x_of_ix": "x0_m + ix * dx_m", "y_of_iy": "y0_m + iy * dy_m (iy = 0 sampled at 0.5 mm)",
                 "mirror": "the field at (x, -y) is (ux, -uy, uz, k, epsilon, p) at (x, y)"},
        "fields": FIELDS,
        "units": UNITS,
        "data_file": name + ".f32",
        "dtype": "float32",
        "byte_order": "little",
        "array_order": "[height][field][iy][ix], C order",
        "shape": [len(HEIGHTS), len(FIELDS), GRID_NY, GRID_NX],
        "missing_points": missing,
        "interpolation": "cellPoint",
        "peak_speed_z015": {"speed_m_s": float(spd15.flat[k]),
                            "x_m": float(xg[k % GRID_NX]), "y_m": float(yg[k // GRID_NX])},
        "csv": {"centreline": name + "_centreline.csv", "axisline": name + "_axisline.csv",
                "walljet": name + "_walljet.csv"},
    }
    if model_of(case) != DEFAULT_MODEL:
        # the turbulence-model study: its model, and the k-epsilon case it is compared with
        hdr["turbulence_model"] = model_of(case)
        hdr["reference_case"] = case["reference_case"]
        hdr["reference_data"] = "data/cfd/%s.json" % case["reference_case"]
        if model_of(case) == "realizableKE":
            hdr["k_min_m2_s2"] = RKE_KMIN
        if model_of(case) == "kOmegaSST":
            hdr["inlet"]["omega_1_s"] = inlet.get("omega_inlet")
            hdr["ambient"]["omega_1_s"] = omega_of(K_AMB, EPS_AMB)
            hdr["units"] = dict(UNITS, epsilon="m^2/s^3 (from the model's omega: C_mu k omega, C_mu = 0.09)")
    with open(os.path.join(out_dir, name + ".json"), "w") as fh:
        json.dump(hdr, fh, indent=1)
        fh.write("\n")
    print("converted: peak %.2f m/s at z 1.5 cm, s = %s" % (hdr["peak_speed_z015"]["speed_m_s"],
                                                             "%.3f m" % s_x if s_x is not None else "?"))


def mesh_clock(case_dir):
    """Elapsed seconds of snappyHexMesh (the bulk of the meshing), from its log."""
    p = os.path.join(case_dir, "log.snappyHexMesh")
    if not os.path.exists(p):
        return None
    m = re.findall(r"Finished meshing in = ([0-9.]+)", open(p, errors="replace").read())
    return int(round(float(m[-1]))) if m else None


def stagnation_from_line(x, ux, c):
    """Where ux changes sign from - to + near c (linear interpolation)."""
    best = None
    for i in range(len(x) - 1):
        if ux[i] < 0 <= ux[i + 1] and abs(x[i] - c) < 1.0:
            xs = x[i] - ux[i] * (x[i + 1] - x[i]) / (ux[i + 1] - ux[i])
            if best is None or abs(xs - c) < abs(best - c):
                best = float(xs)
    return best


def main(argv):
    if len(argv) < 2:
        sys.exit(__doc__)
    cmd = argv[1]
    if cmd == "list":
        for c in campaign(argv[2] if len(argv) > 2 else DEFAULT_MODEL):
            print("%s %g %d %g" % (c["name"], c["tilt_deg"], c["mesh_level"], c["inlet_d"]))
    elif cmd == "write":
        cmd_write(argv[2], argv[3])
    elif cmd == "fields":
        cmd_fields(argv[2], argv[3])
    elif cmd == "progress":
        cmd_progress(argv[2])
    elif cmd == "sampledict":
        cmd_sampledict(argv[2], argv[3])
    elif cmd == "convert":
        cmd_convert(argv[2], argv[3], argv[4])
    else:
        sys.exit(__doc__)


if __name__ == "__main__":
    main(sys.argv)
