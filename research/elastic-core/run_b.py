"""Model B: a coarse lattice core of cell h, the surface tied to it (spring kappa = c_k E / h per
area) or embedded; membrane tension T = c_t E h. Usage: run_b.py punch|beam h c_k c_t [mode]"""
import sys
from core import *
what, h, ck, ct = sys.argv[1], float(sys.argv[2]), float(sys.argv[3]), float(sys.argv[4])
mode = sys.argv[5] if len(sys.argv) > 5 else "spring"
mu = E / 2
case = Punch() if what == "punch" else Beam()
gpos, tets, wt, W, node_tet = grid_core(case.Xs, case.T, h)
corot = len(sys.argv) > 6 and sys.argv[6] == 'corot'
core = Core(gpos, tets, wt, mu)
name = ("corot " if corot else "") + "B %s h %.1f mm ck %g ct %g (%d core nodes)" % (mode, 1e3 * h, ck, ct, len(gpos))
if what == "punch":
    m = Model(case.Xs, case.T, case.pres, core, mode, T_cap=ct * E * h, kappa=ck * E / h, W=W, node_tet=node_tet if corot else None)
    u, f, its = case.run(m)
    report_punch(name, case, u, f, its)
else:
    for w in ("stretch", "bend", "twist"):
        pres = case.case(w)[3]
        m = Model(case.Xs, case.T, pres, core, mode, T_cap=ct * E * h, kappa=ck * E / h, W=W, node_tet=node_tet if corot else None)
        u, its = case.run(m, w)
        report_beam(name, case, w, u, its)
