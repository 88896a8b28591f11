#!/usr/bin/python3
"""DOLFINx's P1 sag of the clamped foam bar (scenes/foam_bar_clamped.json) at a Poisson's ratio.

The reference of the statics test near incompressibility (tests/cli/statics_cli_test.cpp,
NearlyIncompressibleBarSagsAsDolfinxOrIsRefusedWithTheRange): the same 16x4x4 box mesh (six
Kuhn tets per cell, as make_box_mesh), E = 2e5 Pa, density 40 kg/m^3, gravity 9.81 m/s^2, the
nodes at x <= -0.139 clamped; the problem and solver of scripts/compare_dolfinx.py (whose
functions it uses), Newton to 1e-6 x the weight. Linear tets lock near incompressibility, so
the answer to compare with is this discretisation's, not the beam's. Needs Debian's
python3-dolfinx (apt-get install -y --no-install-recommends python3-dolfinx).

    /usr/bin/python3 scripts/dolfinx_sag.py 0.499999     # mean tip sag -6.856398452e-04 m (0.5.2)
    /usr/bin/python3 scripts/dolfinx_sag.py 0.499999814  # -6.844973919e-04 m: the largest nu
                                                         # shapectl accepts for this bar
"""
import os
import sys

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import compare_dolfinx  # noqa: E402


def main():
    nu = float(sys.argv[1]) if len(sys.argv) > 1 else 0.499999
    nodes, tets = compare_dolfinx.box_mesh((0.32, 0.03, 0.03), (16, 4, 4))
    fixed = nodes[:, 0] <= -0.139
    weight = 0.32 * 0.03 * 0.03 * 40 * 9.81
    _, iterations, x, failed = compare_dolfinx.run_dolfinx(
        nodes, tets, dict(E=2e5, nu=nu, rho=40.0), fixed, 1e-6 * weight)
    if x is None:
        sys.exit("nu = %r: DOLFINx did not converge (%d iterations)" % (nu, iterations))
    tip = np.isclose(nodes[:, 0], 0.16)
    print("nu = %r: mean tip sag %.9e m (%d tip nodes, %d iterations%s)"
          % (nu, np.mean(x[tip, 2] - nodes[tip, 2]), tip.sum(), iterations,
             ", SNES with a line search" if failed else ""))


if __name__ == "__main__":
    main()
