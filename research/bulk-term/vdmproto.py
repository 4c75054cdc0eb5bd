"""Prototype of VDM bulk-term variants (scratch, not part of the repo).

Model per docs/model.md: per axis K^d = L_cot(T) + diag(k^d), k_i^d = B (A_i^d)^2 / V_i, one
pressure unknown keeping the volume. Bulk variants measure the bulk displacement against a
reference r_i instead of the rest position:  E_bulk = 1/2 sum_i sum_d k_i^d (u_i^d - r_i^d)^2.
  paper : r = 0
  rigid : r_i = displacement of X_i under the rigid motion fitted (weighted least squares,
          kernel radius rho) to the neighbourhood's current positions (lagged / explicit)
  mean  : r_i = kernel average of u over the neighbourhood (translation only)
A multiscale bulk is a sum of such terms with their own B and rho.
"""
import os
import numpy as np
import scipy.sparse as sp
import scipy.sparse.linalg as spla
from scipy.spatial import cKDTree

D = os.environ.get("BULK_TERM_DATA", "data") + "/"


def load(name):
    X = np.loadtxt(D + name + "_X.txt")
    T = np.loadtxt(D + name + "_T.txt", dtype=int)
    return X, T


def cot_weights(X, T):
    I, J, W = [], [], []
    for k in range(3):
        a, b, c = T[:, k], T[:, (k + 1) % 3], T[:, (k + 2) % 3]
        u, v = X[b] - X[a], X[c] - X[a]
        cot = np.einsum("ij,ij->i", u, v) / np.linalg.norm(np.cross(u, v), axis=1)
        I.append(np.minimum(b, c)); J.append(np.maximum(b, c)); W.append(0.5 * cot)
    I, J, W = np.concatenate(I), np.concatenate(J), np.concatenate(W)
    n = len(X)
    M = sp.coo_matrix((W, (I, J)), shape=(n, n)).tocsr()
    M.sum_duplicates()
    M = M.tocoo()
    return M.row, M.col, M.data


def laplacian(n, I, J, w):
    W = sp.coo_matrix((w, (I, J)), shape=(n, n))
    W = W + W.T
    return (sp.diags(np.asarray(W.sum(axis=1)).ravel()) - W).tocsr()


def area_vectors(x, T):
    S = 0.5 * np.cross(x[T[:, 1]] - x[T[:, 0]], x[T[:, 2]] - x[T[:, 0]])
    A = np.zeros_like(x)
    for k in range(3):
        np.add.at(A, T[:, k], S / 3)
    return A


def volume(x, T, origin):
    a, b, c = x[T[:, 0]] - origin, x[T[:, 1]] - origin, x[T[:, 2]] - origin
    return np.einsum("ij,ij->i", a, np.cross(b, c)).sum() / 6


def skew(v):
    z = np.zeros(len(v))
    return np.stack([np.stack([z, -v[:, 2], v[:, 1]], -1), np.stack([v[:, 2], z, -v[:, 0]], -1),
                     np.stack([-v[:, 1], v[:, 0], z], -1)], 1)


class Neighbourhood:
    """Kernel neighbourhoods of radius rho (Euclidean ball at rest), weights |A_j| (1 - d^2/rho^2)^2."""

    def __init__(self, X, area, rho):
        tree = cKDTree(X)
        lists = tree.query_ball_point(X, rho)
        rows, cols, wts = [], [], []
        for i, js in enumerate(lists):
            js = np.array(js)
            d2 = ((X[js] - X[i]) ** 2).sum(1) / rho ** 2
            w = area[js] * (1 - d2) ** 2
            rows.append(np.full(len(js), i)); cols.append(js); wts.append(w / w.sum())
        self.rows, self.cols, self.w = np.concatenate(rows), np.concatenate(cols), np.concatenate(wts)
        n = len(X)
        self.G = sp.csr_matrix((self.w, (self.rows, self.cols)), shape=(n, n))  # kernel average
        self.X = X
        self.nnz_per_row = len(self.rows) / n

    def rigid_reference(self, x):
        """r_i = c'_i + R_i (X_i - c_i) - X_i, the rigid fit (Kabsch) to x over the kernel."""
        X, G = self.X, self.G
        c = G @ X
        cp = G @ x
        # S_i = sum_j w_ij (x_j - c'_i)(X_j - c_i)^T = sum_j w x_j X_j^T - c'_i c_i^T
        S = np.zeros((len(X), 3, 3))
        for a in range(3):
            for b in range(3):
                S[:, a, b] = G @ (x[:, a] * X[:, b])
        S -= np.einsum("ia,ib->iab", cp, c)
        U, s, Vt = np.linalg.svd(S)
        det = np.sign(np.linalg.det(U @ Vt))
        U[:, :, 2] *= det[:, None]
        R = U @ Vt
        return cp + np.einsum("iab,ib->ia", R, X - c) - X

    def linear_rigid_operator(self):
        """P (3n x 3n, axis-major blocks) with r = P u for the linearised rigid fit."""
        X, n = self.X, len(self.X)
        rows, cols, vals = [], [], []
        c = self.G @ X
        for i in range(n):
            s, e = self.G.indptr[i], self.G.indptr[i + 1]
            js, w = self.G.indices[s:e], self.G.data[s:e]
            Mj = np.concatenate([np.broadcast_to(np.eye(3), (len(js), 3, 3)), -skew(X[js] - c[i])], 2)  # m x 3 x 6
            H = np.einsum("j,jak,jal->kl", w, Mj, Mj)
            Mi = np.concatenate([np.eye(3), -skew((X[i] - c[i])[None])[0]], 1)
            Pi = np.einsum("ak,kl,jbl->jab", Mi, np.linalg.pinv(H), Mj) * w[:, None, None]  # m x 3 x 3
            for a in range(3):
                for b in range(3):
                    rows.append(a * n + i + 0 * js); cols.append(b * n + js); vals.append(Pi[:, a, b])
        return sp.csr_matrix((np.concatenate(vals), (np.concatenate(rows), np.concatenate(cols))), shape=(3 * n, 3 * n))


class Model:
    def __init__(self, X, T, fixed, B, Bij, bulk_terms=(("paper", 1.0, None),), corot=False):
        """bulk_terms: (kind, share of B, rho) each; kind in paper, rigid, mean, rigidlin, meanlin."""
        self.X, self.T, self.n = X, T, len(X)
        self.origin = X.mean(0)
        self.V0 = volume(X, T, self.origin)
        A0 = area_vectors(X, T)
        self.area0 = np.linalg.norm(A0, axis=1)
        self.Atot = self.area0.sum()
        self.tension = Bij * self.V0 / self.Atot
        I, J, w = cot_weights(X, T)
        self.I, self.J, self.w = I, J, self.tension * w
        self.L = laplacian(self.n, I, J, self.w)
        self.fixed = fixed.astype(bool)
        self.B = B
        self.corot = corot
        self.terms = []
        for kind, share, rho in bulk_terms:
            if kind == "obj":
                self.terms.append((kind, share, None, rho)); continue
            nb = Neighbourhood(X, self.area0, rho) if rho else None
            P = None
            if kind == "rigidlin": P = nb.linear_rigid_operator()
            if kind == "meanlin": P = sp.block_diag([nb.G] * 3).tocsr()
            self.terms.append((kind, share * B, nb, P))

    def bulk_diag(self, A, x):
        Vi = volume(x, self.T, self.origin) * np.linalg.norm(A, axis=1) / np.linalg.norm(A, axis=1).sum()
        return A ** 2 / Vi[:, None]  # times B per term

    def rotations(self, x):
        X = self.X
        S = np.zeros((self.n, 3, 3))
        e = x[self.I] - x[self.J]; d = X[self.I] - X[self.J]
        outer = self.w[:, None, None] * np.einsum("ea,eb->eab", e, d)
        np.add.at(S, self.I, outer); np.add.at(S, self.J, outer)
        U, s, Vt = np.linalg.svd(S)
        det = np.sign(np.linalg.det(U @ Vt))
        U[:, :, 2] *= det[:, None]
        return U @ Vt

    def corot_load(self, R):
        d = self.X[self.I] - self.X[self.J]
        M = 0.5 * (R[self.I] + R[self.J]) - np.eye(3)
        g = self.w[:, None] * np.einsum("eab,eb->ea", M, d)
        f = np.zeros((self.n, 3))
        np.add.at(f, self.I, g); np.add.at(f, self.J, -g)
        return f

    def solve(self, u, mask, values, it_max=1, tol=1e-10, anderson=0, verbose=False):
        """One quasi-static step from u: constrained entries (mask, n x 3) to values; returns u, dP, iterations."""
        n = self.n
        C = (mask | self.fixed).T.ravel()  # axis-major
        vals = np.where(self.fixed, 0.0, values).T.ravel()
        F = ~C
        hist_x, hist_g = [], []
        dP = 0
        for it in range(it_max):
            x = self.X + u
            A = area_vectors(x, self.T)
            Vx = volume(x, self.T, self.origin)
            k = self.bulk_diag(A, x)
            diag = np.zeros((n, 3)); f = np.zeros((n, 3))
            extra = None
            for kind, Bs, nb, P in self.terms:
                diag += Bs * k
                if kind == "obj": f += Bs * k * P.reference(x); continue
                if kind == "rigid": f += Bs * k * nb.rigid_reference(x)
                elif kind == "mean": f += Bs * k * (nb.G @ u)
                elif kind in ("rigidlin", "meanlin"):
                    term = -sp.diags((Bs * k).T.ravel()) @ P
                    extra = term if extra is None else extra + term
            if self.corot: f += self.corot_load(self.rotations(x))
            K = sp.block_diag([self.L + sp.diags(diag[:, d]) for d in range(3)]).tocsr()
            if extra is not None: K = (K + extra).tocsr()
            a = A.T.ravel(); uf = u.T.ravel()
            c = self.V0 - Vx + a @ uf
            KFF = K[F][:, F]; KFC = K[F][:, C]
            rhs = f.T.ravel()[F] - KFC @ vals[C]
            M = sp.bmat([[KFF, -a[F][:, None]], [a[F][None, :], None]]).tocsc()
            z = spla.spsolve(M, np.concatenate([rhs, [c - a[C] @ vals[C]]]))
            new = np.empty(3 * n); new[F] = z[:-1]; new[C] = vals[C]
            dP = z[-1]
            self.reaction = (K @ new - f.T.ravel() - dP * a).reshape(3, n).T
            g = new - uf
            du = np.abs(g).max()
            if anderson and it > 0:
                hist_x.append(uf); hist_g.append(g)
                hist_x, hist_g = hist_x[-anderson:], hist_g[-anderson:]
                if len(hist_g) >= 2:
                    dG = np.stack([hist_g[j + 1] - hist_g[j] for j in range(len(hist_g) - 1)], 1)
                    dX = np.stack([hist_x[j + 1] - hist_x[j] for j in range(len(hist_x) - 1)], 1)
                    gamma = np.linalg.lstsq(dG, g, rcond=None)[0]
                    nxt = uf + g - (dX + dG) @ gamma
                else:
                    nxt = new
            else:
                if anderson: hist_x.append(uf); hist_g.append(g)
                nxt = new
            u = nxt.reshape(3, n).T.copy()
            if verbose: print(it, du)
            if du < tol * 0.1: break
        return u, dP, it + 1


def top_uz(X, T, u, top, px, py):
    P = X
    for t in range(len(T)):
        a, b, c = T[t]
        if min(P[a, 2], P[b, 2], P[c, 2]) < top - 1e-9: continue
        x1, y1, x2, y2 = P[b, 0] - P[a, 0], P[b, 1] - P[a, 1], P[c, 0] - P[a, 0], P[c, 1] - P[a, 1]
        det = x1 * y2 - x2 * y1
        qx, qy = px - P[a, 0], py - P[a, 1]
        l1 = (qx * y2 - x2 * qy) / det; l2 = (x1 * qy - qx * y1) / det; l0 = 1 - l1 - l2
        if min(l0, l1, l2) < -1e-12: continue
        return l0 * u[a, 2] + l1 * u[b, 2] + l2 * u[c, 2]
    raise RuntimeError("no triangle")


class Punch:
    a = 0.005
    FEM = dict(force=0.0403, dent=[-0.406e-3, -0.262e-3, -0.140e-3, -0.085e-3])

    def __init__(self):
        self.X, self.T = load("punch")
        self.fixed = np.loadtxt(D + "punch_fixed.txt", dtype=int).astype(bool)
        self.moved = np.loadtxt(D + "punch_moved.txt", dtype=int)
        self.top = self.X[:, 2].max()
        # top triangles for interpolation
        self.topT = self.T[(self.X[self.T, 2].min(1) > self.top - 1e-9)]

    def dent(self, u):
        out = []
        for f in (1.5, 2, 3, 4):
            s = 0
            for k in range(8):
                phi = 2 * np.pi * (k + 0.5) / 8
                s += top_uz(self.X, self.topT, u, self.top, f * self.a * np.cos(phi), f * self.a * np.sin(phi))
            out.append(s / 8)
        return np.array(out)

    def run(self, model, steps=4, depth=0.001, it_max=1, **kw):
        n = len(self.X)
        u = np.zeros((n, 3))
        mask = np.zeros((n, 3), bool); mask[self.moved] = True
        iters = 0
        for s in range(1, steps + 1):
            vals = np.zeros((n, 3)); vals[self.moved, 2] = -depth * s / steps
            u, dP, it = model.solve(u, mask, vals, it_max=it_max, **kw)
            iters += it
        # force: the reaction on the moved nodes, K u - dP a - f at those entries (z only)
        force = -model.reaction[self.moved, 2].sum()
        return u, iters, force

    def report(self, name, model, u, iters=None, force=None):
        d = self.dent(u)
        rel = 100 * (d / np.array(self.FEM["dent"]) - 1)
        s = f"{name:34s}"
        if force is not None: s += f" force {force:.4f} N ({100 * (force / self.FEM['force'] - 1):+.0f} %)"
        s += " dent " + " ".join(f"{1e3 * x:.3f}({r:+.0f}%)" for x, r in zip(d, rel))
        if iters: s += f" it {iters}"
        print(s, flush=True)
        return d, rel


class Beam:
    FEM = {"stretch": [4.88e-3, 10.04e-3, 15.59e-3], "bend": [3.32e-3, 10.00e-3, 17.01e-3],
           "twist": [1.32e-3, 2.61e-3, 4.00e-3]}

    def __init__(self, name=None):
        name = name or os.environ.get("BEAM", "beam")   # beam (4 cells across) or beam6 (dump.cpp beam6)
        self.name = name
        self.X, self.T = load(name)
        self.abc = np.loadtxt(D + f"{name}_abc.txt", dtype=int)
        self.fixed = np.loadtxt(D + f"{name}_stretch_fixed.txt", dtype=int).astype(bool)
        self.cases = {}
        for c in ("stretch", "bend", "twist"):
            moved = np.loadtxt(D + f"{name}_{c}_moved.txt", dtype=int)
            targets = [np.loadtxt(D + f"{name}_{c}_target{k}.txt") for k in range(10)]
            self.cases[c] = (moved, targets)

    def run(self, model, case, it_max=200, anderson=8, tol=1e-10, steps=None):
        n = len(self.X)
        moved, targets = self.cases[case]
        u = np.zeros((n, 3)); mask = np.zeros((n, 3), bool); mask[moved] = True
        iters = 0
        for k, t in enumerate(targets):
            if steps and (k + 1) % (10 // steps): continue
            vals = np.zeros((n, 3)); vals[moved] = t
            u, dP, it = model.solve(u, mask, vals, it_max=it_max, anderson=anderson, tol=tol * 0.1)
            iters += it
        return u, iters

    def errors(self, case, u):
        m = np.linalg.norm(u[self.abc], axis=1)
        return 100 * (m / np.array(self.FEM[case]) - 1)
