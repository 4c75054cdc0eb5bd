#!/bin/bash
# the rule on the punch the engine's way (4 steps, nonlinear), after the 6-cell beams
export OMP_NUM_THREADS=1 OPENBLAS_NUM_THREADS=1 BULK_TERM_DATA=data PYTHONPATH=. CONE=45 RIGID_ANCHOR=1 C_R=1
while pgrep -f "beam_lbulk.py 0.3 0.5 0.01 1 corot-thick" >/dev/null; do sleep 5; done
/usr/bin/python3 punch_lbulk.py 0.3 0.5 0.01 1 corot-thick 20,1.5
