"""Local-thickness multi-scale bulk (auxiliary-field form), with the membrane or corotational capsule.

Per level s = 0..S-1 and node i a scale rho_si = c_h h_i / 2^s (h_i the local thickness,
thickness.py), kept while rho_si >= c_l l_i (l_i the node's mean edge length); per level an
auxiliary field v_s (per axis), tied to u by springs k_si^d = B_si (A_i^d)^2 / V_i with
B_si = beta E (V/A) / rho_si (per-area stiffness beta E / rho_si), and smoothed by a membrane of
tension beta E rho_s (cotangent weights, rho of the edge = mean of its ends), corotated with the
capsule's rotations when the capsule is. Eliminating v_s gives per level the per-area stiffness
beta E/rho (q rho)^2 / (1 + (q rho)^2): nothing for a translation (nor, corotated, a rotation),
a Winkler spring below rho, and beyond rho (q rho < 1) a membrane of tension beta E rho.

Per axis one SPD system of (S+1) n unknowns (u and the S fields), one pressure unknown for the
three axes (Schur complement of the volume row), rotations and geometry lagged by one
iteration, Anderson mixing on the whole state.
"""
import numpy as np, scipy.sparse as sp, scipy.sparse.linalg as spla, time
from vdmproto import *
from thickness import edge_length


import os
C_R = float(os.environ.get("C_R", "1"))   # aux_corot "thick": rotation ball radius / local thickness


def edge_load(X, I, J, w, R):
    d = X[I] - X[J]
    M = 0.5 * (R[I] + R[J]) - np.eye(3)
    g = w[:, None] * np.einsum("eab,eb->ea", M, d)
    f = np.zeros((len(X), 3))
    np.add.at(f, I, g); np.add.at(f, J, -g)
    return f


class LBulk:
    def __init__(self, X, T, fixed, h, E=3000.0, beta=0.3, c_h=0.5, c_l=1.0, S=None, bij=0.2535,
                 corot=True, aux_corot=None, Bpaper=0.0, anchor=None):
        """anchor: (beta_a, c_a, cnodes) adds lanchor.py's boundary anchor (diagonal and load)."""
        self.m = Model(X, T, fixed, 1.0, bij * E)      # capsule, geometry, rotations
        m = self.m; n = m.n
        self.n, self.E, self.corot = n, E, corot
        self.aux_corot = corot if aux_corot is None else aux_corot
        self.VA = m.V0 / m.Atot
        ell = edge_length(X, T)
        if S is None: S = int(np.ceil(np.log2((c_h * h / (c_l * ell)).max()))) + 1
        rho = c_h * h[None, :] / 2.0 ** np.arange(S)[:, None]          # S x n
        on = rho >= c_l * ell[None, :]
        on[0] = True                                                    # the largest level everywhere
        keep = on.any(1); rho, on = rho[keep], on[keep]
        self.S, self.rho, self.on = len(rho), rho, on
        self.Bs = np.where(on, beta * E * self.VA / rho, 0.0)          # S x n, multiplies (A^d)^2 / V_i
        Lc = m.w / m.tension                                            # unit-tension cot weights
        self.ws = [Lc * beta * E * 0.5 * (r[m.I] + r[m.J]) for r in rho]   # tension beta E rho per level
        self.Ls = [laplacian(n, m.I, m.J, w) for w in self.ws]
        self.Bpaper = Bpaper
        self.anchor = None
        if anchor is not None:
            from lanchor import Anchor, CONE, inward_normals
            beta_a, c_a, cnodes = anchor
            an = Anchor(X, m.area0, c_a * h, cnodes, None if CONE is None else np.radians(CONE), inward_normals(X, T))
            self.anchor = (beta_a * E * self.VA / (c_a * h) * an.f, an)
        self.uc = np.zeros((n, 3))
        self.v = np.zeros((self.S, n, 3))
        # aux_corot == "scale": each level corotated with rotations fitted over its own balls
        # (Kabsch over radius rho_si, Wendland weights) instead of the capsule's 1-ring rotations
        self.G = None
        if self.aux_corot in ("scale", "thick"):
            # "thick": one rotation per node fitted over a ball of radius c_r h_i (through the body),
            # used for every level: the rotation of the body's section, not of the surface patch
            from scipy.spatial import cKDTree
            tree = cKDTree(X); self.G = []
            for r in (rho if self.aux_corot == "scale" else [C_R * h]):
                lists = tree.query_ball_point(X, r)
                rows, cols, wts = [], [], []
                for i, js in enumerate(lists):
                    js = np.array(js); d2 = ((X[js] - X[i]) ** 2).sum(1) / r[i] ** 2
                    w = m.area0[js] * np.clip(1 - d2, 0, None) ** 2
                    rows.append(np.full(len(js), i)); cols.append(js); wts.append(w / w.sum())
                self.G.append(sp.csr_matrix((np.concatenate(wts), (np.concatenate(rows), np.concatenate(cols))), shape=(n, n)))

    def level_rotations(self, x):
        X = self.m.X; out = []
        for G in self.G:
            c = G @ X; cp = G @ x
            S = np.zeros((len(X), 3, 3))
            for a in range(3):
                for b in range(3):
                    S[:, a, b] = G @ (x[:, a] * X[:, b])
            S -= np.einsum("ia,ib->iab", cp, c)
            U, sv, Vt = np.linalg.svd(S)
            det = np.sign(np.linalg.det(U @ Vt)); U[:, :, 2] *= det[:, None]
            R = U @ Vt
            bad = ~(sv[:, 1] > 1e-6 * np.maximum(sv[:, 0], 1e-300))   # ball too small to fix a rotation
            R[bad] = np.eye(3)
            out.append(R)
        return out

    def stats(self):
        n, S = self.n, self.S
        nnzL = self.m.L.nnz
        per_axis = (S + 1) * n, nnzL * (1 + S) + 2 * self.on.sum() + n * 0
        return dict(levels=S, unknowns_per_axis=per_axis[0], nnz_per_axis=per_axis[1],
                    membrane_unknowns=n, membrane_nnz=nnzL, springs=int(self.on.sum()),
                    rho_mm=[(round(1e3 * r.min(), 2), round(1e3 * r.max(), 1)) for r in self.rho])

    def matrices(self, u):
        m, n, S = self.m, self.n, self.S
        x = m.X + u
        A = area_vectors(x, m.T); Vx = volume(x, m.T, m.origin)
        k = m.bulk_diag(A, x)                                           # (A^d)^2 / V_i
        R = m.rotations(x) if (self.corot or self.aux_corot is True) else None
        g0 = m.corot_load(R) if self.corot else np.zeros((n, 3))
        if self.aux_corot == "scale":
            gs = [edge_load(m.X, m.I, m.J, w, Rs) for w, Rs in zip(self.ws, self.level_rotations(x))]
        elif self.aux_corot == "thick":
            Rt = self.level_rotations(x)[0]
            gs = [edge_load(m.X, m.I, m.J, w, Rt) for w in self.ws]
        else:
            gs = [edge_load(m.X, m.I, m.J, w, R) if self.aux_corot else np.zeros((n, 3)) for w in self.ws]
        mats, rhs = [], []
        aref = self.anchor[1].apply(self.uc) if self.anchor else None
        for d in range(3):
            ks = [self.Bs[s] * k[:, d] for s in range(S)]
            rows = [[None] * (S + 1) for _ in range(S + 1)]
            ka = self.anchor[0] * k[:, d] if self.anchor else 0.0
            rows[0][0] = m.L + sp.diags(sum(ks) + self.Bpaper * k[:, d] + ka)
            if self.anchor: g0[:, d] = g0[:, d] + ka * aref[:, d]
            for s in range(S):
                rows[0][s + 1] = sp.diags(-ks[s]); rows[s + 1][0] = sp.diags(-ks[s])
                rows[s + 1][s + 1] = self.Ls[s] + sp.diags(ks[s] + 1e-12 * self.E * m.area0)
            mats.append(sp.bmat(rows).tocsc())
            rhs.append(np.concatenate([g0[:, d]] + [g[:, d] for g in gs]))
        return mats, rhs, A, Vx

    def state(self, u):
        return np.concatenate([np.concatenate([u[:, d]] + [self.v[s][:, d] for s in range(self.S)]) for d in range(3)])

    def unpack(self, z):
        n, S = self.n, self.S
        size = (S + 1) * n
        u = np.stack([z[d * size:d * size + n] for d in range(3)], 1)
        v = np.stack([np.stack([z[d * size + (s + 1) * n:d * size + (s + 2) * n] for d in range(3)], 1) for s in range(S)])
        return u, v

    def solve(self, u, mask, values, it_max=200, tol=1e-10, anderson=8):
        """One quasi-static step; returns u, iterations, last change."""
        m, n, S = self.m, self.n, self.S
        size = (S + 1) * n
        C_u = (mask | m.fixed)
        vals_u = np.where(m.fixed, 0.0, values)
        self.uc = np.where(C_u, vals_u, 0.0)
        hx, hg = [], []
        z = self.state(u)
        for it in range(it_max):
            u, self.v = self.unpack(z)
            mats, rhs, A, Vx = self.matrices(u)
            c = m.V0 - Vx + (A * u).sum()
            xr, xa, idx_all, new = [], [], [], z.copy()
            Ksave = []
            for d in range(3):
                Cd = np.zeros(size, bool); Cd[:n] = C_u[:, d]
                vd = np.zeros(size); vd[:n] = vals_u[:, d]
                ad = np.zeros(size); ad[:n] = A[:, d]
                F = ~Cd
                K = mats[d]
                b = rhs[d][F] - K[F][:, Cd] @ vd[Cd]
                lu = spla.splu(K[F][:, F].tocsc())
                xr.append(lu.solve(b)); xa.append(lu.solve(ad[F]))
                idx_all.append((F, vd, ad, K))
            num = c - sum(ad[~F] @ vd[~F] for F, vd, ad, K in idx_all) - sum(ad[F] @ r for (F, vd, ad, K), r in zip(idx_all, xr))
            den = sum(ad[F] @ a for (F, vd, ad, K), a in zip(idx_all, xa))
            dP = num / den
            react = np.zeros((n, 3))
            for d, ((F, vd, ad, K), r, a) in enumerate(zip(idx_all, xr, xa)):
                zd = vd.copy(); zd[F] = r + dP * a
                new[d * size:(d + 1) * size] = zd
                react[:, d] = (K @ zd - rhs[d] - dP * ad)[:n]
            self.reaction, self.dP = react, dP
            gvec = new - z
            du = np.abs(gvec).max()
            if anderson:
                hx.append(z.copy()); hg.append(gvec.copy())
                hx, hg = hx[-(anderson + 1):], hg[-(anderson + 1):]
                if len(hg) >= 2:
                    dG = np.stack([hg[j + 1] - hg[j] for j in range(len(hg) - 1)], 1)
                    dX = np.stack([hx[j + 1] - hx[j] for j in range(len(hx) - 1)], 1)
                    gam = np.linalg.lstsq(dG, gvec, rcond=None)[0]
                    z = z + gvec - (dX + dG) @ gam
                else:
                    z = new
            else:
                z = new
            if du < tol: break
            if not (self.corot or self.aux_corot) and it_max == 1: break
        u, self.v = self.unpack(new)
        return u, it + 1, du

    def volume_error(self, u):
        m = self.m
        return abs(volume(m.X + u, m.T, m.origin) - m.V0) / m.V0


def run_punch(p, lb, steps=4, depth=1e-3, it_max=60, tol=1e-11):
    n = lb.n; u = np.zeros((n, 3)); mask = np.zeros((n, 3), bool); mask[p.moved] = True
    its = 0
    for s in range(1, steps + 1):
        vals = np.zeros((n, 3)); vals[p.moved, 2] = -depth * s / steps
        u, it, du = lb.solve(u, mask, vals, it_max=it_max, tol=tol); its += it
    force = -lb.reaction[p.moved, 2].sum()
    return u, its, force


def run_beam(b, lb, case, steps=5, it_max=200, tol=1e-10, verbose=False):
    moved, targets = b.cases[case]
    n = lb.n; u = np.zeros((n, 3)); mask = np.zeros((n, 3), bool); mask[moved] = True
    lb.v[:] = 0
    its = 0; t = time.time()
    for k, tg in enumerate(targets):
        if (k + 1) % (10 // steps): continue
        vals = np.zeros((n, 3)); vals[moved] = tg
        u, it, du = lb.solve(u, mask, vals, it_max=it_max, tol=tol); its += it
        if verbose: print("   step", k, it, "%.1e" % du, b.errors(case, u).round(1), f"{time.time() - t:.0f}s", flush=True)
    return u, its, du
