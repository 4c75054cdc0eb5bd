"""Local thickness per surface node: the shape diameter (distance along the inward normal to the
opposite surface), as the median over a cone of rays (axis + 8 rays at `cone` radians), so that
a node on a convex edge or a corner takes the thickness of the body behind it."""
import numpy as np
from vdmproto import area_vectors


def ray_hits(O, Dr, X, T, skip, chunk=256):
    """Nearest t > 0 along each ray O + t D over all triangles not incident to node skip[k]."""
    P0, P1, P2 = X[T[:, 0]], X[T[:, 1]], X[T[:, 2]]
    e1, e2 = P1 - P0, P2 - P0
    out = np.full(len(O), np.inf)
    for s in range(0, len(O), chunk):
        o, d, sk = O[s:s + chunk], Dr[s:s + chunk], skip[s:s + chunk]
        p = np.cross(d[:, None, :], e2[None])                  # r x m x 3
        det = np.einsum("rmk,mk->rm", p, e1)
        ok = np.abs(det) > 1e-18
        inv = np.where(ok, 1 / np.where(ok, det, 1), 0)
        tv = o[:, None, :] - P0[None]
        a = np.einsum("rmk,rmk->rm", tv, p) * inv
        q = np.cross(tv, e1[None])
        b = np.einsum("rk,rmk->rm", d, q) * inv
        t = np.einsum("mk,rmk->rm", e2, q) * inv
        hit = ok & (a >= -1e-9) & (b >= -1e-9) & (a + b <= 1 + 1e-9) & (t > 1e-9)
        hit &= ~(T[None, :, :] == sk[:, None, None]).any(-1)
        out[s:s + chunk] = np.where(hit, t, np.inf).min(1)
    return out


def shape_diameter(X, T, cone=0.5, rays=8):
    A = area_vectors(X, T)
    n = -A / np.linalg.norm(A, axis=1, keepdims=True)          # inward
    # an orthonormal frame per node
    a = np.where(np.abs(n[:, :1]) < 0.9, np.array([[1.0, 0, 0]]), np.array([[0, 1.0, 0]]))
    t1 = np.cross(n, a); t1 /= np.linalg.norm(t1, axis=1, keepdims=True)
    t2 = np.cross(n, t1)
    dirs = [n]
    for k in range(rays):
        ph = 2 * np.pi * k / rays
        dirs.append(np.cos(cone) * n + np.sin(cone) * (np.cos(ph) * t1 + np.sin(ph) * t2))
    N = len(X)
    ts = []
    for d in dirs:
        t = ray_hits(X, d, X, T, np.arange(N))
        ts.append(t * np.einsum("ik,ik->i", d, n))                 # projected on the normal
    ts = np.stack(ts, 1)
    ts[~np.isfinite(ts)] = np.nan
    return np.nanmedian(ts, 1)


def edge_length(X, T):
    """Mean length of the edges at each node."""
    s = np.zeros(len(X)); c = np.zeros(len(X))
    for k in range(3):
        a, b = T[:, k], T[:, (k + 1) % 3]
        l = np.linalg.norm(X[a] - X[b], axis=1)
        np.add.at(s, a, l); np.add.at(c, a, 1); np.add.at(s, b, l); np.add.at(c, b, 1)
    return s / c


if __name__ == "__main__":
    import sys, time
    from vdmproto import load, D
    for name in sys.argv[1:]:
        X, T = load(name)
        t = time.time(); h = shape_diameter(X, T)
        np.savetxt(D + name + "_thickness.txt", h)
        print(name, "thickness mm: min %.1f median %.1f max %.1f" % tuple(1e3 * np.percentile(h, [0, 50, 100])),
              "edge mm: min %.2f max %.2f" % (1e3 * edge_length(X, T).min(), 1e3 * edge_length(X, T).max()),
              f"{time.time() - t:.0f}s")
