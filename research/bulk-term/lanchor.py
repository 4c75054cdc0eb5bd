"""Below-thickness rigid-fit bulk (lrigid.py, c_h <= 1) plus a boundary anchor: a Winkler spring
towards the motion of the constrained nodes (held or prescribed on every axis) found in a ball of
radius rho_a = c_a h_i, weighted by their share f_i of the ball's kernel weight:

    E_anchor = 1/2 sum_i sum_d beta_a E (V/A)/rho_a,i  f_i (A_i^d)^2/V_i (u_i^d - ubar_i^d)^2,
    ubar_i = kernel mean of u over the constrained nodes in the ball (known: prescribed values).

A node whose ball holds no constrained node gets nothing (no rigid motion anchored); a node within
about c_a h of a held base (the punch block's top) gets a foundation. Per axis it is a diagonal and
a load: the per-axis SPD system keeps its pattern.

Usage: lanchor.py punch beta c_h beta_a c_a bij [c_l]
       lanchor.py beam|beam_membrane beta c_h beta_a c_a bij c_l cases
"""
import numpy as np, sys, time
from vdmproto import *
from dense_rigid import linear_solve
from lrigid import make_terms, cost
from beam_dense import P_dense


import os
ISO = os.environ.get("ISO") == "1"
if ISO:
    _bd = Model.bulk_diag
    def _iso(self, A, x):
        k = _bd(self, A, x)
        return np.repeat(k.sum(1, keepdims=True), 3, 1)
    Model.bulk_diag = _iso


class Anchor:
    kind = "anchor"

    def __init__(self, X, area, rho, cnodes, cone=None, inward=None):
        """cone (radians): count only the constrained nodes seen within this angle of the node's
        inward normal, i.e. across the body (the punch block's held base), not beside it (a
        beam's clamp seen from its side faces)."""
        d2 = ((X[:, None, :] - X[None, :, :]) ** 2).sum(-1) / rho[:, None] ** 2
        Phi = np.where(d2 < 1, (1 - d2) ** 2, 0.0) * area[None, :]
        tot = Phi.sum(1)
        PhiC = Phi * cnodes[None, :]
        if cone is not None:
            dX = X[None, :, :] - X[:, None, :]
            cosang = np.einsum("ijk,ik->ij", dX, inward) / np.maximum(np.linalg.norm(dX, axis=2), 1e-30)
            PhiC = PhiC * (cosang >= np.cos(cone))
        sC = PhiC.sum(1)
        self.f = sC / tot
        self.W = PhiC / np.where(sC > 0, sC, 1)[:, None]
        self.nb = (PhiC > 0).sum(1).mean()

        self.X = X

    def apply(self, u):
        if not RIGID_ANCHOR: return self.W @ u
        # the rigid motion (Kabsch) of the constrained nodes in the ball, at X_i; the mean where
        # they do not fix a rotation (fewer than 3 or collinear)
        X, W = self.X, self.W
        out = W @ u
        rows = np.where(self.f > 0)[0]
        c = W[rows] @ X; cp = W[rows] @ (X + u)
        S = np.einsum("ij,ja,jb->iab", W[rows], X + u, X) - np.einsum("ia,ib->iab", cp, c)
        Uu, sv, Vt = np.linalg.svd(S)
        det = np.sign(np.linalg.det(Uu @ Vt))
        Uu[:, :, 2] *= det[:, None]
        R = Uu @ Vt
        ok = sv[:, 1] > 1e-6 * np.maximum(sv[:, 0], 1e-300)
        r = cp + np.einsum("iab,ib->ia", R, X[rows] - c) - X[rows]
        out[rows[ok]] = r[ok]
        return out


RIGID_ANCHOR = os.environ.get("RIGID_ANCHOR") == "1"
CONE = float(os.environ["CONE"]) if os.environ.get("CONE") else None   # degrees


def inward_normals(X, T):
    A = area_vectors(X, T)
    return -A / np.linalg.norm(A, axis=1, keepdims=True)


def anchor_term(X, T, area, VA, h, E, beta_a, c_a, cnodes):
    rho = c_a * h
    A = Anchor(X, area, rho, cnodes, None if CONE is None else np.radians(CONE), inward_normals(X, T))
    return (beta_a * E * VA / rho * A.f)[:, None], A


def solve_step(m, terms, u, mask, values, it_max=300, tol=1e-11, corot=True, anderson=6):
    """beam_dense.solve_step with anchor terms (their reference from the prescribed values) and
    Anderson mixing of the iterates (the capsule's rotations and the fits lag by one iteration)."""
    n = m.n
    hx, hg = [], []
    C = (mask | m.fixed).T.ravel(); F = ~C
    vals = np.where(m.fixed, 0.0, values).T.ravel()
    L = m.L.toarray()
    for it in range(it_max):
        x = m.X + u
        A = area_vectors(x, m.T); Vx = volume(x, m.T, m.origin)
        k = m.bulk_diag(A, x)
        K = np.zeros((3 * n, 3 * n)); f = np.zeros((n, 3))
        for d in range(3): K[d * n:(d + 1) * n, d * n:(d + 1) * n] = L
        uf = u.T.ravel()
        uc = np.where(C, vals, uf).reshape(3, n).T
        for Bs, D in terms:
            kk = (Bs * k).T.ravel()
            K[np.arange(3 * n), np.arange(3 * n)] += kk
            if isinstance(D, Anchor):
                f += Bs * k * D.apply(uc); continue
            P = P_dense(D, x)
            K -= kk[:, None] * P
            f += Bs * k * D.reference(x)
            f -= (kk * (P @ uf)).reshape(3, n).T
        if corot: f += m.corot_load(m.rotations(x))
        a = A.T.ravel(); c = m.V0 - Vx + a @ uf
        nf = F.sum()
        M = np.zeros((nf + 1, nf + 1))
        M[:nf, :nf] = K[np.ix_(F, F)]; M[:nf, nf] = -a[F]; M[nf, :nf] = a[F]
        rhs = np.concatenate([f.T.ravel()[F] - K[np.ix_(F, C)] @ vals[C], [c - a[C] @ vals[C]]])
        z = np.linalg.solve(M, rhs)
        new = np.empty(3 * n); new[F] = z[:-1]; new[C] = vals[C]
        g = new - uf
        du = np.abs(g).max()
        nxt = new
        if anderson:
            hx.append(uf.copy()); hg.append(g.copy())
            hx, hg = hx[-(anderson + 1):], hg[-(anderson + 1):]
            if len(hg) >= 2:
                dG = np.stack([hg[j + 1] - hg[j] for j in range(len(hg) - 1)], 1)
                dX = np.stack([hx[j + 1] - hx[j] for j in range(len(hx) - 1)], 1)
                gam = np.linalg.lstsq(dG, g, rcond=None)[0]
                nxt = uf + g - (dX + dG) @ gam
                nxt[C] = vals[C]
        u = nxt.reshape(3, n).T.copy()
        if du < tol: u = new.reshape(3, n).T.copy(); break
    return u, it + 1, du


if __name__ == "__main__":
    what = sys.argv[1]; E = 3000.0
    beta, ch, beta_a, c_a, bij = (float(x) for x in sys.argv[2:7])
    cl = float(sys.argv[7]) if len(sys.argv) > 7 else 2.0
    if what == "punch":
        p = Punch(); h = np.loadtxt(D + "punch_thickness.txt")
        n = len(p.X); mask = np.zeros((n, 3), bool); mask[p.moved] = True
        vals = np.zeros((n, 3)); vals[p.moved, 2] = -0.001
        m = Model(p.X, p.T, p.fixed, 1.0, bij * E); VA = m.V0 / m.Atot
        cnodes = (mask | p.fixed).all(1).astype(float)
        t = time.time()
        terms, rho, on = make_terms(p.X, p.T, m.area0, VA, h, E, beta, ch, cl) if beta > 0 else ([], [], [])
        if beta_a > 0: terms.append(anchor_term(p.X, p.T, m.area0, VA, h, E, beta_a, c_a, cnodes))
        u, R, info = linear_solve(m, terms, mask, vals)
        F = -R[p.moved, 2].sum()
        p.report(f"{'iso ' if ISO else ''}{'cone %g ' % CONE if CONE else ''}rigid b {beta:g} c_h {ch:g} + anchor b_a {beta_a:g} c_a {c_a:g} Bij/E {bij:g}", m, u, force=F)
        verr = abs(volume(m.X + u, m.T, m.origin) - m.V0) / m.V0
        print("    nb per level", cost(terms, n), "gmres info", info, "vol err (linear, rest) %.1e" % verr, f"{time.time() - t:.0f}s", flush=True)
    else:
        b = Beam(); h = np.loadtxt(D + b.name + "_thickness.txt")
        corot = what == "beam"
        cases = sys.argv[8].split(",")
        m = Model(b.X, b.T, b.fixed, 1.0, bij * E); VA = m.V0 / m.Atot
        for case in cases:
            moved, targets = b.cases[case]
            n = m.n; u = np.zeros((n, 3)); mask = np.zeros((n, 3), bool); mask[moved] = True
            cnodes = (mask | b.fixed).all(1).astype(float)
            terms, rho, on = make_terms(b.X, b.T, m.area0, VA, h, E, beta, ch, cl) if beta > 0 else ([], [], [])
            if beta_a > 0: terms.append(anchor_term(b.X, b.T, m.area0, VA, h, E, beta_a, c_a, cnodes))
            t = time.time(); its = 0
            for kk, tg in enumerate(targets):
                if (kk + 1) % 2: continue
                vals = np.zeros((n, 3)); vals[moved] = tg
                u, it, du = solve_step(m, terms, u, mask, vals, it_max=150, corot=corot)
                its += it
                print('   step', kk, it, '%.1e' % du, b.errors(case, u).round(1), f'{time.time() - t:.0f}s', flush=True)
            verr = abs(volume(m.X + u, m.T, m.origin) - m.V0) / m.V0
            print(f"{case:8s} {'corot' if corot else 'membrane'} {'iso ' if ISO else ''}{'cone %g ' % CONE if CONE else ''}rigid b {beta:g} c_h {ch:g} + anchor b_a {beta_a:g} c_a {c_a:g} Bij/E {bij:g}: A B C",
                  b.errors(case, u).round(1), "it", its, "last du %.1e" % du, "vol err %.1e" % verr, f"{time.time() - t:.0f}s", flush=True)
