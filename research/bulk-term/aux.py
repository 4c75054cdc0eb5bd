"""Sparse multi-scale bulk by auxiliary fields: per scale s a copy v_s of the surface's
displacement, tied to u by the bulk springs k_s = B_s (A_i^d)^2 / V_i and smoothed by its own
membrane of tension T_s = B_s (A/V) rho_s^2 (cotangent Laplacian; corotated with the capsule's
rotations when corot). Eliminating v_s gives the bulk stiffness per area B_s A/V (q rho_s)^2/(1 + (q rho_s)^2):
no stiffness for a translation (and with corot, for a rotation), a Winkler spring at scales below rho_s."""
import numpy as np, scipy.sparse as sp, scipy.sparse.linalg as spla, sys, time
from vdmproto import *


def aux_solve(m, scales, u, mask, values, corot, it_max=1, tol=1e-11, v=None):
    n = m.n; S = len(scales)
    Lc = m.L / m.tension  # unit-tension cotangent Laplacian
    C = (mask | m.fixed).T.ravel(); vals = np.where(m.fixed, 0.0, values).T.ravel()
    if v is None: v = [np.zeros((n, 3)) for _ in range(S)]
    VA = m.V0 / m.Atot
    for it in range(it_max):
        x = m.X + u
        A = area_vectors(x, m.T); Vx = volume(x, m.T, m.origin)
        k = m.bulk_diag(A, x)
        g = m.corot_load(m.rotations(x)) / m.tension if corot else np.zeros((n, 3))  # per unit tension
        blocks_rows = []
        size = n * (S + 1)
        mats, rhss = [], []
        for d in range(3):
            rows = [[None] * (S + 1) for _ in range(S + 1)]
            kd = [Bs * k[:, d] for Bs, rho in scales]
            rows[0][0] = m.L + sp.diags(sum(kd))
            for s, (Bs, rho) in enumerate(scales):
                Ts = Bs / VA * rho ** 2
                rows[0][s + 1] = sp.diags(-kd[s]); rows[s + 1][0] = sp.diags(-kd[s])
                rows[s + 1][s + 1] = sp.diags(kd[s]) + Ts * Lc
            mats.append(sp.bmat(rows).tocsr())
            f = np.zeros(size); f[:n] = g[:, d] * m.tension
            for s, (Bs, rho) in enumerate(scales): f[(s + 1) * n:(s + 2) * n] = g[:, d] * Bs / VA * rho ** 2
            rhss.append(f)
        K = sp.block_diag(mats).tocsr(); f = np.concatenate(rhss)
        # global index of u entry (d, i): d*size + i
        uidx = np.concatenate([d * size + np.arange(n) for d in range(3)])
        Cg = np.zeros(3 * size, bool); Cg[uidx[C]] = True
        valg = np.zeros(3 * size); valg[uidx] = vals
        a = np.zeros(3 * size); a[uidx] = A.T.ravel()
        state = np.zeros(3 * size); state[uidx] = u.T.ravel()
        for s in range(S):
            for d in range(3): state[d * size + (s + 1) * n + np.arange(n)] = v[s][:, d]
        c = m.V0 - Vx + a @ state
        F = ~Cg
        # per axis: K_d,FF x = b by LU, the pressure by the Schur complement of the volume row
        sols_r, sols_a, idxs = [], [], []
        rhs_full = f - K[:, Cg] @ valg[Cg]
        for d in range(3):
            blk = np.zeros(3 * size, bool); blk[d * size:(d + 1) * size] = True
            idx = np.where(blk & F)[0]
            lu = spla.splu(K[idx][:, idx].tocsc())
            sols_r.append(lu.solve(rhs_full[idx])); sols_a.append(lu.solve(a[idx])); idxs.append(idx)
        # u = x_r + dP x_a;  a.u = c - a_C.vals_C
        num = c - a[Cg] @ valg[Cg] - sum(a[i] @ x for i, x in zip(idxs, sols_r))
        den = sum(a[i] @ x for i, x in zip(idxs, sols_a))
        dPn = num / den
        z = np.zeros(F.sum() + 1)
        new = valg.copy()
        for i, xr, xa in zip(idxs, sols_r, sols_a): new[i] = xr + dPn * xa
        z[-1] = dPn
        du = np.abs(new - state).max()
        m.reaction = ((K @ new - f - z[-1] * a)[uidx]).reshape(3, n).T
        u = new[uidx].reshape(3, n).T.copy()
        v = [np.stack([new[d * size + (s + 1) * n + np.arange(n)] for d in range(3)], 1) for s in range(S)]
        if du < tol: break
    return u, v, it + 1, du


def scales_rule(VA, E, cmax, S, beta):
    return [(beta * E * VA / r, r) for r in [cmax * VA / 2 ** s for s in range(S)]]


if __name__ == "__main__":
    what = sys.argv[1]; E = 3000
    cmax, S, beta, bij = float(sys.argv[2]), int(sys.argv[3]), float(sys.argv[4]), float(sys.argv[5])
    if what == "punch":
        p = Punch(); m = Model(p.X, p.T, p.fixed, 1, bij * E); VA = m.V0 / m.Atot
        sc = scales_rule(VA, E, cmax, S, beta)
        n = m.n; mask = np.zeros((n, 3), bool); mask[p.moved] = True
        u = np.zeros((n, 3)); v = None; its = 0
        for st in range(1, 5):
            vals = np.zeros((n, 3)); vals[p.moved, 2] = -0.001 * st / 4
            u, v, it, du = aux_solve(m, sc, u, mask, vals, corot=False, it_max=1, v=v); its += it
        p.report(f"aux c{cmax:g} S{S} beta {beta:g} Bij/E {bij:g}", m, u, force=-m.reaction[p.moved, 2].sum())
    else:
        b = Beam(); m = Model(b.X, b.T, b.fixed, 1, bij * E); VA = m.V0 / m.Atot
        sc = scales_rule(VA, E, cmax, S, beta)
        for case in sys.argv[6].split(','):
            moved, targets = b.cases[case]
            n = m.n; u = np.zeros((n, 3)); v = None; mask = np.zeros((n, 3), bool); mask[moved] = True
            t = time.time(); its = 0
            for kk, tg in enumerate(targets):
                if (kk + 1) % 2: continue
                vals = np.zeros((n, 3)); vals[moved] = tg
                u, v, it, du = aux_solve(m, sc, u, mask, vals, corot=True, it_max=150, v=v); its += it
                print('  step', kk, it, '%.1e' % du, b.errors(case, u).round(1), f'{time.time()-t:.0f}s', flush=True)
            print(f"{case:8s} aux c{cmax:g} S{S} beta {beta:g} Bij/E {bij:g}: A B C", b.errors(case, u).round(1),
                  "it", its, "last du %.1e" % du, f"{time.time()-t:.0f}s", flush=True)
