"""Writes slit_bar.node / slit_bar.ele (TetGen, 0-based): the test bar (0.32 x 0.03 x 0.03 m along
x, centred at the origin, 16 x 2 x 5 hexahedra of 6 tetrahedra each) with a slit 2 mm high
through its middle for |x| < 0.12 m: two slabs, 14 mm thick, joined at both ends. A load
pressing the upper slab's middle down brings its lower face onto the lower slab's upper face:
self-contact (docs/contact.md). Run from this directory: python3 slit_bar.py"""
import itertools

XS = [-0.16 + 0.02 * i for i in range(17)]
YS = [-0.015, 0.0, 0.015]
ZS = [-0.015, -0.0075, -0.001, 0.001, 0.0075, 0.015]


def volume(a, b, c, d):
    u, v, w = ([q[t] - a[t] for t in range(3)] for q in (b, c, d))
    return (u[0] * (v[1] * w[2] - v[2] * w[1]) - u[1] * (v[0] * w[2] - v[2] * w[0])
            + u[2] * (v[0] * w[1] - v[1] * w[0]))


points, index = [], {}
for k, z in enumerate(ZS):
    for j, y in enumerate(YS):
        for i, x in enumerate(XS):
            index[i, j, k] = len(points)
            points.append((round(x, 6), y, z))
tets = []
for i, j, k in itertools.product(range(len(XS) - 1), range(len(YS) - 1), range(len(ZS) - 1)):
    if k == 2 and 2 <= i < 14:
        continue  # the slit
    corner = lambda b: index[i + (b & 1), j + (b >> 1 & 1), k + (b >> 2 & 1)]
    # Kuhn's six tetrahedra around the diagonal from corner 0 to corner 7 (conforming).
    for a, b, _ in itertools.permutations([1, 2, 4]):
        t = [corner(0), corner(a), corner(a | b), corner(7)]
        if volume(*(points[n] for n in t)) < 0:
            t[1], t[2] = t[2], t[1]
        tets.append(t)
with open("slit_bar.node", "w") as f:
    f.write(f"{len(points)} 3 0 0\n")
    f.writelines(f"{n} {p[0]:g} {p[1]:g} {p[2]:g}\n" for n, p in enumerate(points))
with open("slit_bar.ele", "w") as f:
    f.write(f"{len(tets)} 4 0\n")
    f.writelines(f"{n} {t[0]} {t[1]} {t[2]} {t[3]}\n" for n, t in enumerate(tets))
