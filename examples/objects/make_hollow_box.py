# An open box of five 5 mm walls and a 5 mm lid (24 x 16 x 10 cm), faces subdivided at ~1 cm, as one
# OBJ whose groups name the parts (base, lid), as a scanned hollow box arrives. Then:
#   python3 examples/objects/make_hollow_box.py && bimart object import hollow_box.obj --top lid \
#       --pivot 0 0.08 0.10 --axis -1 0 0 --category box --out examples/objects/hollow_box
import math
def cuboid(lo, hi, step=0.01):
    V, F = [], []
    idx = {}
    def vid(p):
        k = tuple(round(c, 7) for c in p)
        if k not in idx:
            idx[k] = len(V); V.append(k)
        return idx[k]
    for axis in range(3):
        for side in (0, 1):
            u, w = [a for a in range(3) if a != axis]
            nu = max(1, math.ceil((hi[u] - lo[u]) / step)); nw = max(1, math.ceil((hi[w] - lo[w]) / step))
            def P(i, j):
                p = [0, 0, 0]
                p[axis] = hi[axis] if side else lo[axis]
                p[u] = lo[u] + (hi[u] - lo[u]) * i / nu
                p[w] = lo[w] + (hi[w] - lo[w]) * j / nw
                return vid(p)
            for i in range(nu):
                for j in range(nw):
                    a, b, c, d = P(i, j), P(i + 1, j), P(i + 1, j + 1), P(i, j + 1)
                    # outward normal: +axis when side=1; (u, w, axis) right-handed?
                    rh = (axis, u, w) in [(0, 1, 2), (1, 2, 0), (2, 0, 1)]
                    flip = (side == 1) != rh
                    if flip:
                        F += [(a, c, b), (a, d, c)]
                    else:
                        F += [(a, b, c), (a, c, d)]
    return V, F
X, Y, Z, T = 0.12, 0.08, 0.10, 0.005
walls = [
    ((-X, -Y, 0), (X, Y, T)),              # floor
    ((-X, -Y, T), (-X + T, Y, Z)),         # left
    ((X - T, -Y, T), (X, Y, Z)),           # right
    ((-X + T, -Y, T), (X - T, -Y + T, Z)), # front
    ((-X + T, Y - T, T), (X - T, Y, Z)),   # back
]
lid = ((-X, -Y, Z), (X, Y, Z + T))
out = []
base = 1
for name, boxes in (("base", walls), ("lid", [lid])):
    out.append(f"g {name}")
    for lo, hi in boxes:
        V, F = cuboid(lo, hi)
        out += [f"v {p[0]:.6f} {p[1]:.6f} {p[2]:.6f}" for p in V]
        out += [f"f {a+base} {b+base} {c+base}" for a, b, c in F]
        base += len(V)
open("hollow_box.obj", "w").write("\n".join(out) + "\n")
print("vertices", base - 1)
