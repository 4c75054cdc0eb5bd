import numpy as np, sys, time
from vdmproto import *
from dense_rigid import *
p = Punch(); E = 3000
m = Model(p.X, p.T, p.fixed, 1, 0.2535 * E)
VA = m.V0 / m.Atot
n = m.n; mask = np.zeros((n, 3), bool); mask[p.moved] = True
vals = np.zeros((n, 3)); vals[p.moved, 2] = -0.001
cache = {}
def P(rho, kind="rigid"):
    if (rho, kind) not in cache: cache[(rho, kind)] = DenseRigid(p.X, m.area0, rho, kind)
    return cache[(rho, kind)]
def run(name, rhos, beta, bij, kind="rigid"):
    m.L = laplacian(n, m.I, m.J, m.w / m.tension * bij * E * VA)
    # per-area stiffness beta E / rho_s  ->  B_s = beta E (V/A) / rho_s
    terms = [(beta * E * VA / r * (TOP if r == rhos[0] else 1.0), P(r, kind)) for r in rhos]
    u, R, info = linear_solve(m, terms, mask, vals)
    F = -R[p.moved, 2].sum()
    p.report(name, m, u, force=F)
cmax = float(sys.argv[1]); S = int(sys.argv[2]); TOP = float(sys.argv[6]) if len(sys.argv) > 6 else 1.0
rhos = [cmax * VA / 2 ** s for s in range(S)]
print("V/A", VA, "rhos mm", [round(r * 1e3, 1) for r in rhos])
for beta in [float(x) for x in sys.argv[3].split(',')]:
    for bij in [float(x) for x in sys.argv[4].split(',')]:
        run(f"ms c{cmax:g} S{S} beta {beta:g} Bij/E {bij:g}", rhos, beta, bij, sys.argv[5] if len(sys.argv) > 5 else "rigid")
