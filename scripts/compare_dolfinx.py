#!/usr/bin/python3
"""Statics from rest: shapectl against DOLFINx's Newton loop on the same P1 mesh.

A benchmark, not a test (docs/benchmarks.md). Needs Debian's python3-dolfinx (0.5.x; written
for the 0.5/0.6 API) and a built shapectl. For each case it writes the mesh as Gmsh MSH 2.2
and a scene naming it, runs `shapectl statics` on it, then solves the same problem with DOLFINx
(the Newton loop alone timed, as DOLFINx's users would time it) and prints the times, both
Newton iteration counts and the largest distance between the two equilibria. shapectl is timed
twice: its whole solve (set-up, symbolic analysis and Newton, as the CLI reports it on stderr)
and its whole process (also starting the program and reading the files).

The same problem: compressible neo-Hookean energy per unit rest volume
    psi(F) = mu/2 (tr(F^T F) - 3) - mu ln J + lambda/2 (ln J)^2
(shapectl's "kappa" is Lame's lambda: E nu / ((1 + nu)(1 - 2 nu)), src/shapectl/fem/material.cpp),
gravity rho g as a body force (on P1 elements the consistent load equals shapectl's lumped
one: rho g V/4 per node of each tet), the nodes in the clamp boxes fixed at rest. Quadrature
degree 1 is exact for both (F is constant on a linear tet). Tolerance: shapectl stops when
every free node's force is below 1e-6 x the object's weight (relative_tolerance); DOLFINx is
given that force as its absolute tolerance on the residual's 2-norm (never looser than the
largest nodal force) with rtol 0, the residual criterion, and MUMPS via PETSc's LU. Where
DOLFINx's Newton does not converge in 100 iterations (the plate: full steps from rest), the
row instead times PETSc's SNES (newtonls) with a backtracking line search on the energy, as
shapectl's line search, from rest, and says so below it (marked *).

    python3 scripts/compare_dolfinx.py                       # bar 1.5k and 12k, frame, plate
    python3 scripts/compare_dolfinx.py --cases bar12k-tetgen,frame-tetgen   # unstructured
    python3 scripts/compare_dolfinx.py --cases bar12k --repeat 3
    python3 scripts/compare_dolfinx.py --msh my_bar.msh --clamp-x 0.011   # any tet mesh
"""
import argparse
import json
import os
import re
import subprocess
import sys
import tempfile
import time

import numpy as np

# Each timed run starts after this pause: OpenBLAS's idle threads in this process (numpy's,
# and PETSc's after a DOLFINx solve) spin for ~0.1 s after their last call and would take a
# core from the run that follows.
QUIET_SECONDS = 0.3


# --- meshes -----------------------------------------------------------------------------------

def box_mesh(size, cells, hole=None):
    """shapectl's make_box_mesh (src/shapectl/mesh/box_mesh.cpp): a box centred at the origin,
    each cell split into 6 tets along its main diagonal; cells whose centre is in `hole`
    dropped, unused nodes removed. Returns (nodes (n,3), tets (m,4))."""
    nx, ny, nz = cells
    h = np.asarray(size, float) / np.asarray(cells, float)
    lo = -0.5 * np.asarray(size, float)

    def node(i, j, k):
        return i + (nx + 1) * (j + (ny + 1) * k)

    # Kuhn split: the 6 paths from corner 0 to corner 7 along the axes.
    paths = [(0, 1, 2), (0, 2, 1), (1, 0, 2), (1, 2, 0), (2, 0, 1), (2, 1, 0)]
    tets = []
    for k in range(nz):
        for j in range(ny):
            for i in range(nx):
                centre = lo + h * (np.array([i, j, k]) + 0.5)
                if hole is not None and np.all(centre >= hole[0]) and np.all(centre <= hole[1]):
                    continue
                for path in paths:
                    c = [i, j, k]
                    corners = [node(*c)]
                    for axis in path:
                        c[axis] += 1
                        corners.append(node(*c))
                    tets.append(corners)
    grid = np.stack(np.meshgrid(np.arange(nx + 1), np.arange(ny + 1), np.arange(nz + 1),
                                indexing="ij"), axis=-1)
    nodes = (lo + h * grid.transpose(2, 1, 0, 3).reshape(-1, 3))
    tets = np.asarray(tets, dtype=np.int64)
    tets = orient(nodes, tets)
    used = np.unique(tets)
    renumber = -np.ones(len(nodes), dtype=np.int64)
    renumber[used] = np.arange(len(used))
    return nodes[used], renumber[tets]


def orient(nodes, tets):
    """Swaps two corners of every negatively oriented tet."""
    d = nodes[tets[:, 1:]] - nodes[tets[:, :1]]
    negative = np.linalg.det(d) < 0
    tets = tets.copy()
    tets[negative, 1], tets[negative, 2] = tets[negative, 2], tets[negative, 1].copy()
    return tets


def write_msh(path, nodes, tets):
    """Gmsh MSH 2.2 ASCII, linear tets (element type 4), full precision."""
    with open(path, "w") as f:
        f.write("$MeshFormat\n2.2 0 8\n$EndMeshFormat\n$Nodes\n%d\n" % len(nodes))
        for i, p in enumerate(nodes):
            f.write("%d %.17g %.17g %.17g\n" % (i + 1, p[0], p[1], p[2]))
        f.write("$EndNodes\n$Elements\n%d\n" % len(tets))
        for e, t in enumerate(tets):
            f.write("%d 4 2 1 1 %d %d %d %d\n" % (e + 1, t[0] + 1, t[1] + 1, t[2] + 1, t[3] + 1))
        f.write("$EndElements\n")


def read_msh(path):
    """Nodes and linear tets of a Gmsh MSH 2.2 ASCII file (what `--msh` takes)."""
    with open(path) as f:
        lines = [line.strip() for line in f]
    if lines[lines.index("$MeshFormat") + 1].split()[0] != "2.2":
        sys.exit("%s: a Gmsh MSH 2.2 ASCII file expected (gmsh -format msh22)" % path)
    start = lines.index("$Nodes") + 1
    count = int(lines[start])
    index, nodes = {}, []
    for k, line in enumerate(lines[start + 1:start + 1 + count]):
        parts = line.split()
        index[int(parts[0])] = k
        nodes.append([float(v) for v in parts[1:4]])
    start = lines.index("$Elements") + 1
    tets = []
    for line in lines[start + 1:start + 1 + int(lines[start])]:
        parts = [int(v) for v in line.split()]
        if parts[1] == 4:
            tags = parts[2]
            tets.append([index[n] for n in parts[3 + tags:7 + tags]])
    nodes = np.asarray(nodes)
    return nodes, orient(nodes, np.asarray(tets, dtype=np.int64))


def box_surface(lo, hi):
    """The closed, outward-oriented triangle surface of an axis-aligned box: (vertices, faces)."""
    v = np.array([[x, y, z] for z in (lo[2], hi[2]) for y in (lo[1], hi[1]) for x in (lo[0], hi[0])])
    quads = [(0, 2, 3, 1), (4, 5, 7, 6), (0, 1, 5, 4), (2, 6, 7, 3), (0, 4, 6, 2), (1, 3, 7, 5)]
    return v, [t for a, b, c, d in quads for t in ((a, b, c), (a, c, d))]


def frame_surface(outer, inner, thickness):
    """A rectangular frame: the outer rectangle minus the inner one (both centred at the
    origin, sizes in x and y), extruded over z in [-thickness/2, thickness/2]."""
    ox, oy, ix, iy = outer[0] / 2, outer[1] / 2, inner[0] / 2, inner[1] / 2
    ring_outer = [(-ox, -oy), (ox, -oy), (ox, oy), (-ox, oy)]  # counter-clockwise from above
    ring_inner = [(-ix, -iy), (ix, -iy), (ix, iy), (-ix, iy)]
    v = []
    for z in (-thickness / 2, thickness / 2):
        v += [(x, y, z) for x, y in ring_outer] + [(x, y, z) for x, y in ring_inner]
    # Vertex index: ring r (0 outer, 1 inner), corner k, layer l (0 bottom, 1 top).
    def idx(l, r, k):
        return 8 * l + 4 * r + k % 4
    f = []
    for k in range(4):
        # Top and bottom: the trapezoid between the rings on side k.
        f += [(idx(1, 0, k), idx(1, 0, k + 1), idx(1, 1, k + 1)), (idx(1, 0, k), idx(1, 1, k + 1), idx(1, 1, k))]
        f += [(idx(0, 0, k), idx(0, 1, k + 1), idx(0, 0, k + 1)), (idx(0, 0, k), idx(0, 1, k), idx(0, 1, k + 1))]
        # Outer wall facing out, inner wall facing the hole.
        f += [(idx(0, 0, k), idx(0, 0, k + 1), idx(1, 0, k + 1)), (idx(0, 0, k), idx(1, 0, k + 1), idx(1, 0, k))]
        f += [(idx(0, 1, k), idx(1, 1, k + 1), idx(0, 1, k + 1)), (idx(0, 1, k), idx(1, 1, k), idx(1, 1, k + 1))]
    return np.array(v, float), f


def tetgen_mesh(shapectl, workdir, name, surface, max_tet_volume):
    """An unstructured mesh of a closed surface, made by shapectl's TetGen (a scene's surface
    file with max_tet_volume) and read back from `shapectl statics --vtu` with gravity off, so
    that the written points are the rest positions. Returns (nodes (n,3), tets (m,4))."""
    vertices, faces = surface
    obj = os.path.join(workdir, name + ".obj")
    with open(obj, "w") as f:
        f.writelines("v %.17g %.17g %.17g\n" % tuple(p) for p in vertices)
        f.writelines("f %d %d %d\n" % (a + 1, b + 1, c + 1) for a, b, c in faces)
    lo = vertices.min(axis=0)
    scene = {
        "object": {"mesh": {"file": os.path.basename(obj), "max_tet_volume": max_tet_volume},
                   "material": {"youngs_modulus": 2e5, "poisson_ratio": 0.3, "density": 40}},
        "gravity": [0, 0, 0],
        "fixed": {"box": {"min": (lo - 1).tolist(), "max": [lo[0] + 1e-3, 1, 1]}},
    }
    scene_file = os.path.join(workdir, name + "_mesh.json")
    with open(scene_file, "w") as f:
        json.dump(scene, f)
    vtu = os.path.join(workdir, name + ".vtu")
    run = subprocess.run([shapectl, "statics", scene_file, "--out", vtu + ".json", "--vtu", vtu],
                         capture_output=True, text=True)
    if run.returncode != 0:
        sys.exit("shapectl could not mesh %s:\n%s" % (name, run.stderr))
    with open(vtu) as f:
        text = f.read()

    def array(name_attribute, dtype):
        start = text.index('Name="%s"' % name_attribute)
        body = text[text.index(">", start) + 1:text.index("</DataArray>", start)]
        return np.array(body.split(), dtype=dtype)

    nodes = array("Points", float).reshape(-1, 3)
    tets = array("connectivity", np.int64).reshape(-1, 4)
    return nodes, orient(nodes, tets)


# --- the cases --------------------------------------------------------------------------------

BAR = dict(size=(0.32, 0.03, 0.03), E=2e5, nu=0.3, rho=40.0)


def clamped_ends(nodes, depth):
    """Nodes within `depth` of either end along x (the bar and frame are held at both ends)."""
    x = nodes[:, 0]
    return (x <= x.min() + depth) | (x >= x.max() - depth)


def clamped_left(nodes, depth):
    x = nodes[:, 0]
    return x <= x.min() + depth


UNSTRUCTURED = ("bar12k-tetgen", "frame-tetgen")


def make_cases(shapectl=None, workdir=None, names=()):
    """name → (nodes, tets, material, fixed-node mask). The unstructured (TetGen) cases are
    made only when named, by `shapectl` in `workdir`."""
    bar = dict(E=2e5, nu=0.3, rho=40.0)
    frame = dict(E=3e5, nu=0.3, rho=60.0)
    cases = {}
    half = np.array(BAR["size"]) / 2
    for name in set(names) & set(UNSTRUCTURED):
        if name == "bar12k-tetgen":  # about the 12,751-tet Gmsh bar
            nodes, tets = tetgen_mesh(shapectl, workdir, "bar_tetgen", box_surface(-half, half), 6.0e-8)
            cases[name] = (nodes, tets, bar, clamped_ends(nodes, 0.011))
        else:  # about the 2,841-tet frame
            nodes, tets = tetgen_mesh(shapectl, workdir, "frame_tetgen",
                                      frame_surface((0.32, 0.16), (0.24, 0.08), 0.02), 9e-7)
            cases[name] = (nodes, tets, frame, clamped_ends(nodes, 0.011))
    for name, cells in (("bar1.5k", (16, 4, 4)), ("bar12k", (32, 8, 8)), ("bar50k", (51, 13, 13))):
        nodes, tets = box_mesh(BAR["size"], cells)
        cases[name] = (nodes, tets, bar, clamped_ends(nodes, 0.011))
    hole = (np.array([-0.12, -0.04, -0.02]), np.array([0.12, 0.04, 0.02]))
    nodes, tets = box_mesh((0.32, 0.16, 0.02), (16, 8, 2), hole)
    cases["frame"] = (nodes, tets, frame, clamped_ends(nodes, 0.011))
    nodes, tets = box_mesh((0.30, 0.30, 0.005), (60, 60, 1))
    cases["plate"] = (nodes, tets, bar, clamped_left(nodes, 0.001))
    return cases


# --- shapectl ---------------------------------------------------------------------------------

def run_shapectl(shapectl, workdir, name, nodes, tets, material, fixed):
    msh = os.path.join(workdir, name + ".msh")
    write_msh(msh, nodes, tets)
    scene = {
        "object": {
            "mesh": {"file": os.path.basename(msh)},
            "material": {"youngs_modulus": material["E"], "poisson_ratio": material["nu"],
                         "density": material["rho"]},
        },
        "gravity": [0, 0, -9.81],
        "fixed": {"nodes": [int(i) for i in np.flatnonzero(fixed)]},
    }
    scene_file = os.path.join(workdir, name + ".json")
    with open(scene_file, "w") as f:
        json.dump(scene, f)
    out = os.path.join(workdir, name + "_result.json")
    time.sleep(QUIET_SECONDS)
    t0 = time.perf_counter()
    run = subprocess.run([shapectl, "statics", scene_file, "--out", out],
                         capture_output=True, text=True)
    seconds = time.perf_counter() - t0
    if run.returncode != 0:
        sys.exit("shapectl statics failed on %s:\n%s" % (name, run.stderr))
    solve = re.search(r"set-up and Newton ([0-9.eE+-]+) ms", run.stderr)
    if not solve:
        sys.exit("shapectl statics on %s: no solve time on stderr:\n%s" % (name, run.stderr))
    with open(out) as f:
        result = json.load(f)
    x = np.asarray(result["positions"], float).reshape(-1, 3)
    return seconds, 1e-3 * float(solve.group(1)), result["iterations"], x


def point_key(p):
    """A node's coordinates as a dictionary key (rounded to 1e-12 m)."""
    return tuple(np.round(np.asarray(p, float), 12))


# --- DOLFINx ----------------------------------------------------------------------------------

def run_dolfinx(nodes, tets, material, fixed, force_tolerance):
    from mpi4py import MPI
    from petsc4py import PETSc
    import ufl
    import dolfinx
    from dolfinx import fem
    from dolfinx.fem.petsc import NonlinearProblem
    from dolfinx.nls.petsc import NewtonSolver

    domain_element = ufl.Mesh(ufl.VectorElement("Lagrange", ufl.tetrahedron, 1))
    # create_mesh renumbers the nodes: they are matched back by their coordinates below.
    domain = dolfinx.mesh.create_mesh(MPI.COMM_WORLD, tets, nodes, domain_element)
    V = fem.VectorFunctionSpace(domain, ("Lagrange", 1))

    fixed_points = {point_key(p) for p in nodes[fixed]}

    def is_fixed(x):
        return np.array([point_key(x[:, k]) in fixed_points for k in range(x.shape[1])])

    dofs = fem.locate_dofs_geometrical(V, is_fixed)
    zero = np.zeros(3, dtype=PETSc.ScalarType)
    bc = fem.dirichletbc(zero, dofs, V)

    E, nu, rho = material["E"], material["nu"], material["rho"]
    mu = fem.Constant(domain, PETSc.ScalarType(E / (2 * (1 + nu))))
    lmbda = fem.Constant(domain, PETSc.ScalarType(E * nu / ((1 + nu) * (1 - 2 * nu))))
    body = fem.Constant(domain, PETSc.ScalarType((0, 0, -9.81 * rho)))

    u = fem.Function(V)
    v = ufl.TestFunction(V)
    F = ufl.variable(ufl.Identity(3) + ufl.grad(u))
    J = ufl.det(F)
    psi = mu / 2 * (ufl.tr(F.T * F) - 3) - mu * ufl.ln(J) + lmbda / 2 * ufl.ln(J) ** 2
    P = ufl.diff(psi, F)
    dx = ufl.Measure("dx", domain=domain, metadata={"quadrature_degree": 1})
    residual = ufl.inner(ufl.grad(v), P) * dx - ufl.inner(v, body) * dx
    energy = psi * dx - ufl.inner(u, body) * dx

    problem = NonlinearProblem(residual, u, bcs=[bc])
    solver = NewtonSolver(MPI.COMM_WORLD, problem)
    solver.convergence_criterion = "residual"
    solver.atol = force_tolerance
    solver.rtol = 1e-300
    solver.max_it = 100
    solver.report = False
    ksp = solver.krylov_solver
    options = PETSc.Options()
    prefix = ksp.getOptionsPrefix() or ""
    options[prefix + "ksp_type"] = "preonly"
    options[prefix + "pc_type"] = "lu"
    options[prefix + "pc_factor_mat_solver_type"] = "mumps"
    ksp.setFromOptions()

    time.sleep(QUIET_SECONDS)
    t0 = time.perf_counter()
    try:
        iterations, converged = solver.solve(u)
    except RuntimeError:  # full Newton steps can fail to converge (the plate from rest)
        iterations, converged = solver.max_it, False
    seconds = time.perf_counter() - t0
    failed = None
    if not converged:
        # Newton with a backtracking line search (PETSc's SNES), the same tolerance and MUMPS.
        failed = (seconds, iterations)
        u.x.array[:] = 0
        seconds, iterations, converged = solve_with_line_search(
            energy, residual, u, bc, force_tolerance, solver.max_it)
        if not converged:
            return seconds, iterations, None, failed
    # Deformed positions in the original node order (P1: dofs sit at the geometry nodes).
    x_dofs = V.tabulate_dof_coordinates()
    displacement = u.x.array.reshape(-1, 3)
    by_point = {point_key(p): k for k, p in enumerate(x_dofs)}
    order = np.array([by_point[point_key(p)] for p in nodes])
    return seconds, iterations, nodes + displacement[order], failed


def solve_with_line_search(energy, residual, u, bc, force_tolerance, max_it):
    """PETSc SNES newtonls with a backtracking line search on the energy (SNES's objective; as
    shapectl's, whose line search also asks for less energy), from u: the same residual
    criterion (2-norm below force_tolerance), MUMPS LU. Returns (seconds of the SNES solve
    alone, iterations, converged). PETSc's default merit function, the residual norm, stalls
    on the plate from its first step."""
    from petsc4py import PETSc
    import ufl
    from dolfinx import fem
    from dolfinx.fem.petsc import (apply_lifting, assemble_matrix, assemble_vector,
                                   create_matrix, create_vector, set_bc)

    L = fem.form(residual)
    a = fem.form(ufl.derivative(residual, u, ufl.TrialFunction(u.function_space)))

    def set_u(x):
        x.ghostUpdate(addv=PETSc.InsertMode.INSERT, mode=PETSc.ScatterMode.FORWARD)
        x.copy(u.vector)
        u.vector.ghostUpdate(addv=PETSc.InsertMode.INSERT, mode=PETSc.ScatterMode.FORWARD)

    def F(snes, x, b):
        set_u(x)
        with b.localForm() as b_local:
            b_local.set(0.0)
        assemble_vector(b, L)
        apply_lifting(b, [a], bcs=[[bc]], x0=[x], scale=-1.0)
        b.ghostUpdate(addv=PETSc.InsertMode.ADD, mode=PETSc.ScatterMode.REVERSE)
        set_bc(b, [bc], x, -1.0)

    def J(snes, x, A, P):
        A.zeroEntries()
        assemble_matrix(A, a, bcs=[bc])
        A.assemble()

    E = fem.form(energy)

    def objective(snes, x):
        set_u(x)
        value = fem.assemble_scalar(E)
        return value if np.isfinite(value) else np.inf  # an inverted tet: no step there

    b, A = create_vector(L), create_matrix(a)
    snes = PETSc.SNES().create()
    snes.setObjective(objective)
    snes.setFunction(F, b)
    snes.setJacobian(J, A)
    snes.setTolerances(atol=force_tolerance, rtol=1e-300, stol=0.0, max_it=max_it)
    prefix = "line_search_"
    snes.setOptionsPrefix(prefix)
    options = PETSc.Options()
    for key, value in [("snes_type", "newtonls"), ("snes_linesearch_type", "bt"),
                       ("ksp_type", "preonly"), ("pc_type", "lu"),
                       ("pc_factor_mat_solver_type", "mumps")]:
        options[prefix + key] = value
    snes.setFromOptions()
    x = u.vector.copy()
    time.sleep(QUIET_SECONDS)
    t0 = time.perf_counter()
    snes.solve(None, x)
    seconds = time.perf_counter() - t0
    x.copy(u.vector)
    u.x.scatter_forward()
    return seconds, snes.getIterationNumber(), snes.getConvergedReason() > 0


# --- main -------------------------------------------------------------------------------------

def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--shapectl", default=os.path.join("build", "shapectl"))
    parser.add_argument("--cases", default="bar1.5k,bar12k,frame,plate",
                        help="comma-separated: bar1.5k, bar12k, bar50k, frame, plate, and "
                             "unstructured (TetGen through shapectl): bar12k-tetgen, frame-tetgen")
    parser.add_argument("--msh", help="instead: a tet mesh (MSH 2.2 ASCII) clamped at both ends")
    parser.add_argument("--clamp-x", type=float, default=0.011,
                        help="with --msh: clamp depth at each end along x, metres")
    parser.add_argument("--repeat", type=int, default=1, help="runs per case (medians printed)")
    parser.add_argument("--shapectl-only", action="store_true",
                        help="skip DOLFINx (where it is not installed): shapectl's side only")
    args = parser.parse_args()

    names = args.cases.split(",")
    known = list(make_cases()) + list(UNSTRUCTURED)
    unknown = [n for n in names if n not in known]
    if unknown and not args.msh:
        sys.exit("--cases: unknown %s (known: %s)" % (", ".join(unknown), ", ".join(known)))

    print("%-13s %7s | %-24s | %-9s | %-24s | %-22s | %s" % (
        "case", "tets", "shapectl whole solve", "+ process", "DOLFINx Newton loop",
        "ratio: solve (process)", "max |x_shapectl - x_dolfinx|"))
    with tempfile.TemporaryDirectory() as workdir:
        if args.msh:
            nodes, tets = read_msh(args.msh)
            cases = {os.path.basename(args.msh): (nodes, tets, dict(E=2e5, nu=0.3, rho=40.0),
                                                  clamped_ends(nodes, args.clamp_x))}
            names = list(cases)
        else:
            cases = make_cases(args.shapectl, workdir, names)
        for name in names:
            nodes, tets, material, fixed = cases[name]
            # shapectl's tolerance: relative_tolerance (1e-6) x the object's weight.
            d = nodes[tets[:, 1:]] - nodes[tets[:, :1]]
            weight = material["rho"] * np.abs(np.linalg.det(d)).sum() / 6 * 9.81
            tolerance = 1e-6 * weight
            ours, ours_solve, theirs = [], [], []
            plain = []  # where DOLFINx's Newton did not converge: (seconds, iterations)
            for _ in range(args.repeat):
                t, t_solve, it_ours, x_ours = run_shapectl(
                    args.shapectl, workdir, name.replace(".", "_"), nodes, tets, material, fixed)
                ours.append(t)
                ours_solve.append(t_solve)
                if args.shapectl_only:
                    it_theirs, x_theirs = 0, np.full_like(x_ours, np.nan)
                    theirs.append(np.nan)
                    continue
                t, it_theirs, x_theirs, failed = run_dolfinx(nodes, tets, material, fixed,
                                                             tolerance)
                theirs.append(t)
                if failed:
                    plain.append(failed)
            a, s = float(np.median(ours)), float(np.median(ours_solve))
            ours_text = "%-13s %7d | %8.4f s, %2d Newton it | %7.3f s" % (
                name, len(tets), s, it_ours, a)
            if args.shapectl_only:
                print(ours_text + " | (not run)")
            elif x_theirs is None:
                print(ours_text + " | not converged in %d Newton it (%.3f s), nor with a line "
                      "search" % (plain[-1][1], plain[-1][0]))
            else:
                b = float(np.median(theirs))
                print(ours_text + " | %8.3f s, %2d Newton it%s| %5.1fx (%4.1fx)          | %.2e m"
                      % (b, it_theirs, "*" if plain else " ", b / s, b / a,
                         np.abs(x_ours - x_theirs).max()))
                if plain:
                    print("  * DOLFINx's Newton did not converge in %d iterations (%.3f s); this "
                          "is PETSc SNES with a backtracking line search on the energy "
                          "(newtonls, bt), same tolerance and MUMPS"
                          % (plain[-1][1], float(np.median([t for t, _ in plain]))))
            sys.stdout.flush()


if __name__ == "__main__":
    main()
