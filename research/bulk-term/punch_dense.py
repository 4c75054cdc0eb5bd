import numpy as np, sys, time
from vdmproto import *
from dense_rigid import *
p = Punch(); E = 3000
m = Model(p.X, p.T, p.fixed, 1, 0.2535 * E)
VA = m.V0 / m.Atot
n = m.n; mask = np.zeros((n, 3), bool); mask[p.moved] = True
vals = np.zeros((n, 3)); vals[p.moved, 2] = -0.001
def run(name, specs, bij):
    m.L = laplacian(n, m.I, m.J, m.w / m.tension * bij * E * VA)
    terms = [(B, DenseRigid(p.X, m.area0, rho, kind) if rho else None) for B, rho, kind in specs]
    terms2 = [(B, P) for B, P in terms]
    # plain Winkler terms (rho None) have P u = 0
    class Zero:
        def apply(self, u): return 0 * u
    terms2 = [(B, P if P else Zero()) for B, P in terms]
    u, R, info = linear_solve(m, terms2, mask, vals)
    F = -R[p.moved, 2].sum()
    p.report(name, m, u, force=F)
run("linear plain rule", [(0.0892 * E, None, None)], 0.2535)
for rho in [float(x) * 1e-3 for x in sys.argv[1].split(',')]:
    for beta in [float(x) for x in sys.argv[2].split(',')]:
        for bij in [float(x) for x in sys.argv[3].split(',')]:
            run(f"rigid rho {rho*1e3:.0f} B/E {beta:g} Bij/E {bij:g}", [(beta * E, rho, "rigid")], bij)
