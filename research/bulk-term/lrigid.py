"""Local-thickness multi-scale rigid-fit bulk: per level s and node i a Euclidean ball of radius
rho_si = c_h h_i / 2^s (h_i the local thickness from thickness.py), kept while rho_si >= c_l l_i;
the bulk spring measured against the rigid motion fitted over the ball (Wendland weights |A_j|
(1 - d^2/rho_i^2)^2), per-area stiffness beta E / rho_si. The ball is 3D: once rho reaches across
the body it takes in the nodes of the opposite face (for the punch block the held bottom).

Punch: one linear solve at rest geometry (dense_rigid.linear_solve, GMRES preconditioned by the
plain membrane system). Beams: beam_dense.solve_step (Kabsch fits, linearised implicitly, the
capsule's rotations lagged), corotational or membrane capsule."""
import numpy as np, sys, time
from vdmproto import *
from dense_rigid import DenseRigid, linear_solve
from thickness import edge_length


class LocalRigid(DenseRigid):
    def __init__(self, X, area, rho):
        d2 = ((X[:, None, :] - X[None, :, :]) ** 2).sum(-1) / rho[:, None] ** 2
        Phi = np.where(d2 < 1, (1 - d2) ** 2, 0.0) * area[None, :]
        self.W = Phi / Phi.sum(1, keepdims=True)
        del Phi, d2
        self.X, self.kind = X, "rigid"
        self.c = self.W @ X
        WX2 = self.W @ (X ** 2).sum(1)
        WXX = np.stack([np.stack([self.W @ (X[:, a] * X[:, b]) for b in range(3)], -1) for a in range(3)], -2)
        c = self.c
        J = (WX2 - (c ** 2).sum(1))[:, None, None] * np.eye(3) - (WXX - np.einsum("ia,ib->iab", c, c))
        self.Jinv = np.linalg.pinv(J, rcond=1e-10)
        self.nb = (self.W > 0).sum(1).mean()


def levels(X, T, h, c_h, c_l, S=None):
    ell = edge_length(X, T)
    if S is None: S = int(np.ceil(np.log2((c_h * h / (c_l * ell)).max()))) + 1
    rho = c_h * h[None, :] / 2.0 ** np.arange(S)[:, None]
    on = rho >= c_l * ell[None, :]
    on[0] = True
    keep = on.any(1)
    return rho[keep], on[keep]


def make_terms(X, T, area, VA, h, E, beta, c_h, c_l, cache=None):
    rho, on = levels(X, T, h, c_h, c_l)
    terms = []
    for r, o in zip(rho, on):
        key = (round(c_h, 6), round(float(r.max()), 9))
        P = cache.get(key) if cache is not None else None
        if P is None:
            P = LocalRigid(X, area, r)
            if cache is not None: cache[key] = P
        Bs = np.where(o, beta * E * VA / r, 0.0)[:, None]
        terms.append((Bs, P))
    return terms, rho, on


def cost(terms, n):
    """Nonzeros per row of the bulk's coupling (per axis block and the 3x3 coupling of the fit)."""
    return [round(float(P.nb), 1) for _, P in terms]


if __name__ == "__main__":
    what = sys.argv[1]; E = 3000.0
    betas = [float(x) for x in sys.argv[2].split(",")]
    chs = [float(x) for x in sys.argv[3].split(",")]
    bijs = [float(x) for x in sys.argv[4].split(",")]
    cl = float(sys.argv[5]) if len(sys.argv) > 5 else 1.0
    if what == "punch":
        p = Punch(); h = np.loadtxt(D + "punch_thickness.txt")
        n = len(p.X); mask = np.zeros((n, 3), bool); mask[p.moved] = True
        vals = np.zeros((n, 3)); vals[p.moved, 2] = -0.001
        cache = {}
        for ch in chs:
            for bij in bijs:
                m = Model(p.X, p.T, p.fixed, 1.0, bij * E)
                VA = m.V0 / m.Atot
                for beta in betas:
                    t = time.time()
                    terms, rho, on = make_terms(p.X, p.T, m.area0, VA, h, E, beta, ch, cl, cache)
                    u, R, info = linear_solve(m, terms, mask, vals)
                    F = -R[p.moved, 2].sum()
                    p.report(f"rigid beta {beta:g} c_h {ch:g} c_l {cl:g} Bij/E {bij:g} S{len(rho)}", m, u, force=F)
                    print("    nb per level", cost(terms, n), "gmres info", info, f"{time.time() - t:.0f}s", flush=True)
    else:
        from beam_dense import solve_step
        b = Beam(); h = np.loadtxt(D + b.name + "_thickness.txt")
        corot = what == "beam"          # 'beam' corotational, 'beam_membrane' membrane capsule
        cases = sys.argv[6].split(",") if len(sys.argv) > 6 else ["stretch", "bend", "twist"]
        beta, ch, bij = betas[0], chs[0], bijs[0]
        m = Model(b.X, b.T, b.fixed, 1.0, bij * E)
        VA = m.V0 / m.Atot
        terms, rho, on = make_terms(b.X, b.T, m.area0, VA, h, E, beta, ch, cl)
        print("levels rho mm (min,max):", [(round(1e3 * r.min(), 1), round(1e3 * r.max(), 1)) for r in rho],
              "nb per level", cost(terms, len(b.X)), flush=True)
        for case in cases:
            moved, targets = b.cases[case]
            n = m.n; u = np.zeros((n, 3)); mask = np.zeros((n, 3), bool); mask[moved] = True
            t = time.time(); its = 0
            for kk, tg in enumerate(targets):
                if (kk + 1) % 2: continue
                vals = np.zeros((n, 3)); vals[moved] = tg
                u, it, du = solve_step(m, terms, u, mask, vals, it_max=150, corot=corot)
                its += it
                print('   step', kk, it, '%.1e' % du, b.errors(case, u).round(1), f'{time.time() - t:.0f}s', flush=True)
            verr = abs(volume(m.X + u, m.T, m.origin) - m.V0) / m.V0
            print(f"{case:8s} {'corot' if corot else 'membrane'} rigid beta {beta:g} c_h {ch:g} c_l {cl:g} Bij/E {bij:g}: A B C",
                  b.errors(case, u).round(1), "it", its, "last du %.1e" % du, "vol err %.1e" % verr, f"{time.time() - t:.0f}s", flush=True)
