"""Beams with multi-scale rigid-relative bulk, solved with the bulk term implicit (dense
linearised rigid projection about the current positions) and the capsule rotations lagged."""
import numpy as np, sys, time
from vdmproto import *
from dense_rigid import *


def P_dense(D, x):
    """3n x 3n (axis-major) linearised rigid fit about positions x with D's kernel weights."""
    W = D.W; n = len(x)
    c = W @ x
    WX2 = W @ (x ** 2).sum(1)
    WXX = np.einsum("ij,ja,jb->iab", W, x, x)
    J = (WX2 - (c ** 2).sum(1))[:, None, None] * np.eye(3) - (WXX - np.einsum("ia,ib->iab", c, c))
    Jinv = np.linalg.pinv(J, rcond=1e-10)
    di = skew(x - c)                       # n x 3 x 3
    SJ = np.einsum("iab,ibc->iac", di, Jinv)  # skew(d_i) J_i^-1
    # skew(x_j - c_i) = skew(x_j) - skew(c_i)
    sx = skew(x); sc = skew(c)
    T1 = np.einsum("iac,jcb->ijab", SJ, sx) - np.einsum("iac,icb->iab", SJ, sc)[:, None]
    Pb = W[:, :, None, None] * (np.eye(3) - T1)  # n x n x 3 x 3
    return Pb.transpose(2, 0, 3, 1).reshape(3 * n, 3 * n)


def solve_step(m, terms, u, mask, values, it_max=300, tol=1e-11, corot=True):
    n = m.n
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
        for Bs, D in terms:
            kk = (Bs * k).T.ravel()
            K[np.arange(3 * n), np.arange(3 * n)] += kk
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
        du = np.abs(new - uf).max()
        u = new.reshape(3, n).T.copy()
        if du < tol: break
    return u, it + 1, du


if __name__ == "__main__":
    b = Beam(); E = 3000
    m0 = Model(b.X, b.T, b.fixed, 1, 1); VA = m0.V0 / m0.Atot
    cmax = float(sys.argv[1]); S = int(sys.argv[2]); beta = float(sys.argv[3]); bij = float(sys.argv[4])
    kind = sys.argv[5] if len(sys.argv) > 5 else "rigid"
    cases = sys.argv[6].split(',') if len(sys.argv) > 6 else ["stretch", "bend", "twist"]
    rhos = [cmax * VA / 2 ** s for s in range(S)]
    print("V/A", VA, "rhos mm", [round(r * 1e3, 1) for r in rhos], flush=True)
    terms = [(beta * E * VA / r, DenseRigid(b.X, m0.area0, r, kind)) for r in rhos]
    m = Model(b.X, b.T, b.fixed, 1.0, bij * E)
    for case in cases:
        moved, targets = b.cases[case]
        n = m.n; u = np.zeros((n, 3)); mask = np.zeros((n, 3), bool); mask[moved] = True
        t = time.time(); its = 0
        for kk, tg in enumerate(targets):
            if (kk + 1) % 2: continue
            vals = np.zeros((n, 3)); vals[moved] = tg
            u, it, du = solve_step(m, terms, u, mask, vals, it_max=150)
            print('  step', kk, it, '%.1e' % du, b.errors(case, u).round(1), f'{time.time()-t:.0f}s', flush=True)
            its += it
        print(f"{case:8s} c{cmax:g} S{S} beta {beta:g} Bij/E {bij:g} {kind}: A B C", b.errors(case, u).round(1),
              "it", its, "last du %.1e" % du, f"{time.time()-t:.0f}s", flush=True)
