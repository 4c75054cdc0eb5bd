"""Prototype: VDM's surface (membrane capsule, one pressure keeping the volume) on an elastic
core instead of the per-node bulk spring (issue 26). Research, not part of the product.

The core is a tet mesh carrying an as-rigid-as-possible energy per tet,
    E_core = mu_c sum_t V_t f_t |F_t - R_t|^2      (linearised: mu_c |eps|^2, i.e. nu = 0),
whose per-axis matrix is the same on every axis (rotations R_t lagged, as loads), as the
engine's capsule. Two cores:
  fem   : the FEM mesh's own tets; the surface nodes are core nodes (the model's best case).
  grid  : a coarse lattice of cubes of size h (Kuhn split into 6 tets, f_t the cube's inside
          fraction) that the surface is embedded in. Surface nodes keep their own unknowns,
          tied to the core's interpolated motion by springs of stiffness per area kappa
          (mode "spring"), or are the core's interpolation (mode "embed").
Volume: one pressure, the surface's enclosed volume kept (Newton row on the current area
vectors). Prescribed displacements by a penalty. Nonlinear: the rotations' fixed point with
Anderson mixing.
"""
import os
import sys
import numpy as np
import scipy.sparse as sp
import scipy.sparse.linalg as spla
from scipy.spatial import cKDTree

D = os.environ.get("CORE_DATA", "data") + "/"


def lt(name, dtype=float):
    return np.loadtxt(D + name, dtype=dtype)


def cot_laplacian(X, T, n):
    I, J, W = [], [], []
    for k in range(3):
        a, b, c = T[:, k], T[:, (k + 1) % 3], T[:, (k + 2) % 3]
        u, v = X[b] - X[a], X[c] - X[a]
        cot = np.einsum("ij,ij->i", u, v) / np.linalg.norm(np.cross(u, v), axis=1)
        I.append(b); J.append(c); W.append(0.5 * cot)
    I, J, W = np.concatenate(I), np.concatenate(J), np.concatenate(W)
    Wm = sp.coo_matrix((W, (I, J)), shape=(n, n))
    Wm = (Wm + Wm.T).tocsr()
    return (sp.diags(np.asarray(Wm.sum(1)).ravel()) - Wm).tocsr()


def area_vectors(x, T):
    S = 0.5 * np.cross(x[T[:, 1]] - x[T[:, 0]], x[T[:, 2]] - x[T[:, 0]])
    A = np.zeros_like(x)
    for k in range(3):
        np.add.at(A, T[:, k], S / 3)
    return A


def volume(x, T):
    a, b, c = x[T[:, 0]], x[T[:, 1]], x[T[:, 2]]
    return np.einsum("ij,ij->i", a, np.cross(b, c)).sum() / 6


def tet_gradients(Y, tets):
    """Shape-function gradients G (t x 4 x 3) and volumes of linear tets."""
    Dm = np.stack([Y[tets[:, k]] - Y[tets[:, 0]] for k in (1, 2, 3)], axis=2)  # t x 3 x 3 (columns)
    vol = np.abs(np.linalg.det(Dm)) / 6
    Dinv = np.linalg.inv(Dm)  # rows: gradients of N1..N3
    G = np.zeros((len(tets), 4, 3))
    G[:, 1:, :] = Dinv
    G[:, 0, :] = -Dinv.sum(1)
    return G, vol


class Core:
    def __init__(self, Y, tets, weight, mu):
        self.Y, self.tets = Y, tets
        self.G, vol = tet_gradients(Y, tets)
        self.w = 2 * mu * vol * weight  # per tet: energy mu V f |F - R|^2 -> K = 2 mu V f G G^T
        n = len(Y)
        rows = np.repeat(tets, 4, axis=1).ravel()
        cols = np.tile(tets, (1, 4)).ravel()
        vals = (self.w[:, None, None] * np.einsum("tai,tbi->tab", self.G, self.G)).ravel()
        self.K = sp.coo_matrix((vals, (rows, cols)), shape=(n, n)).tocsr()
        self.n = n

    def rotations(self, y):
        F = np.einsum("tai,taj->tij", y[self.tets], self.G)  # sum_a y_a (x) grad N_a
        U, s, Vt = np.linalg.svd(F)
        det = np.linalg.det(U @ Vt)
        U[:, :, 2] *= np.where(det < 0, -1, 1)[:, None]
        return U @ Vt

    def load(self, R):
        """Per node and axis: sum_t 2 mu V f (R - I)[d,:] . grad N_a (the load of the lagged rotations)."""
        RmI = R - np.eye(3)
        g = self.w[:, None, None] * np.einsum("tdi,tai->tad", RmI, self.G)  # t x 4 x 3
        f = np.zeros((self.n, 3))
        for a in range(4):
            np.add.at(f, self.tets[:, a], g[:, a, :])
        return f


def inside_mask(Xs, Ts, pts):
    """Inside test by the nearest surface triangle's centroid and normal (fine for these shapes)."""
    c = Xs[Ts].mean(1)
    nrm = np.cross(Xs[Ts[:, 1]] - Xs[Ts[:, 0]], Xs[Ts[:, 2]] - Xs[Ts[:, 0]])
    _, j = cKDTree(c).query(pts)
    return np.einsum("ij,ij->i", pts - c[j], nrm[j]) < 0


KUHN = [(0, 1, 3, 7), (0, 1, 5, 7), (0, 2, 3, 7), (0, 2, 6, 7), (0, 4, 5, 7), (0, 4, 6, 7)]


def grid_core(Xs, Ts, h, offset=(0.37, 0.41, 0.29), samples=4):
    """Cubes of size h over the surface's box (shifted by offset*h so that it does not fit the
    shape), kept where some of the cube is inside; Kuhn tets; embedding of the surface nodes."""
    lo = Xs.min(0) - h * (1 - np.array(offset)); hi = Xs.max(0) + h
    dims = np.ceil((hi - lo) / h).astype(int)
    ci = np.stack(np.meshgrid(*[np.arange(d) for d in dims], indexing="ij"), -1).reshape(-1, 3)
    s = (np.arange(samples) + 0.5) / samples
    sub = np.stack(np.meshgrid(s, s, s, indexing="ij"), -1).reshape(-1, 3)
    pts = (lo + h * (ci[:, None, :] + sub[None, :, :])).reshape(-1, 3)
    frac = inside_mask(Xs, Ts, pts).reshape(len(ci), -1).mean(1)
    # cubes holding a surface node are kept too
    cs = np.floor((Xs - lo) / h).astype(int)
    key = lambda c: (c[:, 0] * dims[1] + c[:, 1]) * dims[2] + c[:, 2]
    has_node = np.zeros(len(ci), bool); has_node[key(cs)] = True
    keep = (frac > 0) | has_node
    frac = np.maximum(frac, 0.02)
    corner = np.array([[i >> 2 & 1, i >> 1 & 1, i & 1] for i in range(8)])
    nd = dims + 1
    nkey = lambda c: (c[..., 0] * nd[1] + c[..., 1]) * nd[2] + c[..., 2]
    cubes = ci[keep]
    cn = nkey(cubes[:, None, :] + corner[None, :, :])  # cubes x 8 global node keys
    used, inv = np.unique(cn, return_inverse=True)
    cn = inv.reshape(cn.shape)
    gpos = np.stack(np.unravel_index(used, nd), -1) * h + lo
    tets = np.concatenate([cn[:, list(k)] for k in KUHN])
    wt = np.concatenate([frac[keep]] * 6)
    # embedding: the Kuhn tet holding each surface node
    cube_index = -np.ones(len(ci), int); cube_index[np.where(keep)[0]] = np.arange(keep.sum())
    cid = cube_index[key(cs)]
    loc = (Xs - lo) / h - cs  # in [0,1)^3
    rows, cols, vals, node_tet = [], [], [], []
    for i in range(len(Xs)):
        p = loc[i]
        for k, tk in enumerate(KUHN):
            vs = corner[list(tk)].astype(float)
            M = np.stack([vs[1] - vs[0], vs[2] - vs[0], vs[3] - vs[0]], 1)
            l = np.linalg.solve(M, p - vs[0])
            b = np.array([1 - l.sum(), *l])
            if b.min() > -1e-9:
                rows += [i] * 4; cols += list(cn[cid[i], list(tk)]); vals += list(b)
                node_tet.append(k * len(cubes) + cid[i])
                break
        else:
            raise RuntimeError("node %d in no tet" % i)
    W = sp.coo_matrix((vals, (rows, cols)), shape=(len(Xs), len(gpos))).tocsr()
    return gpos, tets, wt, W, np.array(node_tet)


class Model:
    """Unknowns per axis z = [u (surface, ns); v (core, ng)] (spring) or z = v (embed / fem)."""

    def __init__(self, Xs, Ts, prescribed, core, mode, T_cap=0.0, kappa=0.0, W=None, node_tet=None):
        self.Xs, self.Ts, self.core, self.mode = Xs, Ts, core, mode
        # corotational capsule: each surface node turns with the core tet holding it
        self.node_tet = node_tet
        if node_tet is not None and T_cap > 0:
            Lw = cot_laplacian(Xs, Ts, len(Xs)).tocoo()
            off = Lw.row < Lw.col
            self.eI, self.eJ, self.ew = Lw.row[off], Lw.col[off], -T_cap * Lw.data[off]
        ns, ng = len(Xs), core.n
        self.ns = ns
        Lc = T_cap * cot_laplacian(Xs, Ts, ns) if T_cap > 0 else sp.csr_matrix((ns, ns))
        if mode == "fem":  # surface nodes are the first core nodes
            S = sp.eye(ns, ng, format="csr")
            self.K = core.K + S.T @ Lc @ S
            self.S = S
        elif mode == "embed":
            self.S = W
            self.K = core.K + W.T @ Lc @ W
        elif mode == "spring":
            area = np.linalg.norm(area_vectors(Xs, Ts), axis=1)
            k = sp.diags(kappa * area)
            self.K = sp.bmat([[Lc + k, -k @ W], [-W.T @ k, core.K + W.T @ k @ W]]).tocsr()
            self.S = sp.hstack([sp.eye(ns), sp.csr_matrix((ns, ng))]).tocsr()
        self.N = self.K.shape[0]
        self.V0 = volume(Xs, Ts)
        # prescribed surface dofs (n x 3 bool) by penalty on S rows
        self.pres = prescribed
        self.pen = 1e6 * self.K.diagonal().max()
        self.lu = []
        for d in range(3):
            rows = np.where(prescribed[:, d])[0]
            Sd = self.S[rows]
            self.lu.append(spla.splu((self.K + self.pen * (Sd.T @ Sd)).tocsc()))

    def core_of(self, z):
        if self.mode == "spring":
            return z[self.ns:]
        return z

    def solve_step(self, z, targets, it_max=300, tol=1e-10, anderson=8, verbose=False):
        """targets: ns x 3 prescribed displacement values (used where prescribed)."""
        hx, hg = [], []
        for it in range(it_max):
            u = self.S @ z
            x = self.Xs + u
            A = area_vectors(x, self.Ts)
            c = self.V0 - volume(x, self.Ts) + np.einsum("ij,ij->", A, u) - (A * targets)[self.pres].sum()
            A[self.pres] = 0
            v = self.core_of(z)
            R = self.core.rotations(self.core.Y + v)
            fc = self.core.load(R)
            fs = np.zeros((self.ns, 3))
            if self.node_tet is not None and hasattr(self, "ew"):
                Rn = R[self.node_tet]
                Rb = 0.5 * (Rn[self.eI] + Rn[self.eJ]) - np.eye(3)
                g = self.ew[:, None] * np.einsum("eij,ej->ei", Rb, self.Xs[self.eI] - self.Xs[self.eJ])
                np.add.at(fs, self.eI, g); np.add.at(fs, self.eJ, -g)
            y0, y1 = [], []
            for d in range(3):
                b = np.zeros(self.N)
                if self.mode == "spring":
                    b[self.ns:] = fc[:, d]
                else:
                    b[:] = fc[:, d]
                b += self.S.T @ fs[:, d]
                rows = np.where(self.pres[:, d])[0]
                b += self.pen * (self.S[rows].T @ targets[rows, d])
                a = self.S.T @ A[:, d]
                y0.append(self.lu[d].solve(b)); y1.append(self.lu[d].solve(a))
            aa = [self.S.T @ A[:, d] for d in range(3)]
            lam = (sum(aa[d] @ y0[d] for d in range(3)) - c) / sum(aa[d] @ y1[d] for d in range(3))
            new = np.stack([y0[d] - lam * y1[d] for d in range(3)], 1)
            g = (new - z).ravel()
            du = np.abs(self.S @ (new - z)).max()
            zf = z.ravel()
            if anderson:
                hx.append(zf); hg.append(g)
                hx, hg = hx[-anderson - 1:], hg[-anderson - 1:]
            if anderson and len(hg) >= 2:
                dG = np.stack([hg[j + 1] - hg[j] for j in range(len(hg) - 1)], 1)
                dX = np.stack([hx[j + 1] - hx[j] for j in range(len(hx) - 1)], 1)
                gamma = np.linalg.lstsq(dG, g, rcond=None)[0]
                z = (zf + g - (dX + dG) @ gamma).reshape(z.shape)
            else:
                z = new
            if verbose: print(it, du)
            if du < tol:
                break
        self.lam = lam
        self.reaction = None
        return new, it + 1

    def reaction(self, z, targets):
        pass


def surface_reaction_z(model, z, targets, nodes):
    """Force of the prescribed nodes on the body along z (penalty force)."""
    u = model.S @ z
    return (model.pen * (targets[nodes, 2] - u[nodes, 2])).sum()


# ---------------------------------------------------------------- cases

E = 3000.0


def top_uz(X, T, u, top, px, py):
    for a, b, c in T:
        x1, y1, x2, y2 = X[b, 0] - X[a, 0], X[b, 1] - X[a, 1], X[c, 0] - X[a, 0], X[c, 1] - X[a, 1]
        det = x1 * y2 - x2 * y1
        qx, qy = px - X[a, 0], py - X[a, 1]
        l1 = (qx * y2 - x2 * qy) / det; l2 = (x1 * qy - qx * y1) / det; l0 = 1 - l1 - l2
        if min(l0, l1, l2) < -1e-12: continue
        return l0 * u[a, 2] + l1 * u[b, 2] + l2 * u[c, 2]
    raise RuntimeError("no triangle")


class Punch:
    a = 0.005

    def __init__(self):
        self.P = lt("punch_P.txt"); self.tets = lt("punch_tets.txt", int); self.T = lt("punch_T.txt", int)
        self.ns = int(lt("punch_ns.txt")); self.Xs = self.P[:self.ns]
        self.fixed = lt("punch_fixed.txt", int).astype(bool)
        self.moved = lt("punch_moved.txt", int)
        self.top = self.Xs[:, 2].max()
        self.topT = self.T[(self.Xs[self.T, 2].min(1) > self.top - 1e-9)]
        self.pres = self.fixed.copy(); self.pres[self.moved] = True
        self.fem = {nu: lt("punch_fem_nu%d_u.txt" % nu) for nu in (45, 0)}

    def dent(self, u):
        out = []
        for f in (1.5, 2, 3, 4):
            s = 0
            for k in range(8):
                phi = 2 * np.pi * (k + 0.5) / 8
                s += top_uz(self.Xs, self.topT, u, self.top, f * self.a * np.cos(phi), f * self.a * np.sin(phi))
            out.append(s / 8)
        return np.array(out)

    def run(self, model, steps=4, depth=1e-3, **kw):
        z = np.zeros((model.N, 3)); its = 0
        for k in range(1, steps + 1):
            t = np.zeros((self.ns, 3)); t[self.moved, 2] = -depth * k / steps
            z, n = model.solve_step(z, t, **kw); its += n
        u = model.S @ z
        force = -surface_reaction_z(model, z, t, self.moved)
        return u, force, its


FEM_PUNCH = dict(force=0.0403, dent=np.array([-0.406e-3, -0.262e-3, -0.140e-3, -0.085e-3]))


def report_punch(name, case, u, force, its):
    d = case.dent(u)
    ref = FEM_PUNCH
    vol = (volume(case.Xs + u, case.T) - volume(case.Xs, case.T)) / volume(case.Xs, case.T)
    print("%-40s force %+5.0f %%  dents %s  (mm %s) its %d dV/V %.1e" % (
        name, 100 * (force / ref["force"] - 1),
        " ".join("%+5.0f" % (100 * (d[k] / ref["dent"][k] - 1)) for k in range(4)),
        " ".join("%.3f" % (1e3 * x) for x in d), its, vol), flush=True)


class Beam:
    def __init__(self):
        self.P = lt("beam_P.txt"); self.tets = lt("beam_tets.txt", int); self.T = lt("beam_T.txt", int)
        self.ns = int(lt("beam_ns.txt")); self.Xs = self.P[:self.ns]
        self.abc = lt("beam_abc.txt", int)

    def case(self, w):
        fixed = lt("beam_%s_fixed.txt" % w, int).astype(bool)
        moved = lt("beam_%s_moved.txt" % w, int)
        targets = [lt("beam_%s_target%d.txt" % (w, k)) for k in range(5)]
        pres = fixed.copy(); pres[moved] = True
        fem = lt("beam_%s_fem_nu45_u.txt" % w)
        return fixed, moved, targets, pres, fem

    def run(self, model, w, **kw):
        fixed, moved, targets, pres, fem = self.case(w)
        z = np.zeros((model.N, 3)); its = 0
        for tg in targets:
            t = np.zeros((self.ns, 3)); t[moved] = tg.reshape(len(moved), 3)
            z, n = model.solve_step(z, t, **kw); its += n
        return model.S @ z, its


def report_beam(name, beam, w, u, its):
    fem = beam.case(w)[4]
    a = np.linalg.norm(u[beam.abc], axis=1); r = np.linalg.norm(fem[beam.abc], axis=1)
    vol = (volume(beam.Xs + u, beam.T) - volume(beam.Xs, beam.T)) / volume(beam.Xs, beam.T)
    print("%-40s %-8s %s  its %d dV/V %.1e" % (name, w, " / ".join("%+6.1f" % (100 * (a[k] / r[k] - 1)) for k in range(3)), its, vol), flush=True)


class Liver:
    """The project's liver (level 3, 642 nodes), calibrate's default cases (press, pull)."""

    def __init__(self):
        self.P = lt("liver_P.txt"); self.tets = lt("liver_tets.txt", int); self.T = lt("liver_T.txt", int)
        self.ns = int(lt("liver_ns.txt")); self.Xs = self.P[:self.ns]

    def case(self, c):
        fixed = lt("liver_case%d_fixed.txt" % c, int).astype(bool)
        moved = np.atleast_1d(lt("liver_case%d_moved.txt" % c, int))
        targets = [lt("liver_case%d_target%d.txt" % (c, k)).reshape(len(moved), 3) for k in range(4)]
        pres = fixed.copy(); pres[moved] = True
        return fixed, moved, targets, pres, lt("liver_case%d_fem_nu45_u.txt" % c), lt("liver_case%d_vdm_rule_u.txt" % c)

    def run(self, model, c, **kw):
        fixed, moved, targets, pres = self.case(c)[:4]
        z = np.zeros((model.N, 3)); its = 0
        for tg in targets:
            t = np.zeros((self.ns, 3)); t[moved] = tg
            z, n = model.solve_step(z, t, **kw); its += n
        return model.S @ z, its


def rms_share(u, fem):
    """RMS difference of the final displacements (every component) over the FEM's largest."""
    return np.sqrt(((u - fem) ** 2).mean()) / np.abs(fem).max()
