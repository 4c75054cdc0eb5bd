"""Model A: the ARAP core on the FEM's own tets (+ the surface's volume), punch and beams."""
import sys
from core import *
mu = E / 2
which = sys.argv[1:] or ["punch", "beam"]
if "punch" in which:
    p = Punch()
    print("FEM nu 0 vs 0.45:", end=" "); report_punch("fem nu0", p, p.fem[0], float("nan"), 0)
    core = Core(p.P, p.tets, np.ones(len(p.tets)), mu)
    m = Model(p.Xs, p.T, p.pres, core, "fem")
    u, f, its = p.run(m)
    report_punch("A: ARAP on FEM tets + volume", p, u, f, its)
if "beam" in which:
    b = Beam()
    core = Core(b.P, b.tets, np.ones(len(b.tets)), mu)
    for w in ("stretch", "bend", "twist"):
        fem0 = b.case(w)
        report_beam("FEM nu 0", b, w, lt("beam_%s_fem_nu0_u.txt" % w), 0)
        m = Model(b.Xs, b.T, fem0[3], core, "fem")
        u, its = b.run(m, w)
        report_beam("A: ARAP on FEM tets + volume", b, w, u, its)
