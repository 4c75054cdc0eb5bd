"""Held-out check: the liver's press and pull against the FEM (RMS share of the largest)."""
import sys
from core import *
h, ck, ct = float(sys.argv[1]), float(sys.argv[2]), float(sys.argv[3])
corot = len(sys.argv) > 4 and sys.argv[4] == "corot"
L = Liver()
gpos, tets, wt, W, node_tet = grid_core(L.Xs, L.T, h)
core = Core(gpos, tets, wt, E / 2)
for c in (0, 1):
    pres, fem, rule = L.case(c)[3:]
    m = Model(L.Xs, L.T, pres, core, "spring", T_cap=ct * E * h, kappa=ck * E / h, W=W, node_tet=node_tet if corot else None)
    u, its = L.run(m, c)
    vol = (volume(L.Xs + u, L.T) - volume(L.Xs, L.T)) / volume(L.Xs, L.T)
    print("liver case %d h %.1f mm ck %g ct %g%s (%d core nodes): core %.1f %%, VDM rule %.1f %%  its %d dV/V %.1e" % (
        c, 1e3 * h, ck, ct, " corot" if corot else "", len(gpos), 100 * rms_share(u, fem), 100 * rms_share(rule, fem), its, vol), flush=True)
