#!/bin/bash
# the finer beam surface (6 cells across): the rule fixed on the punch and the skin alone
export OMP_NUM_THREADS=1 OPENBLAS_NUM_THREADS=1 BULK_TERM_DATA=data PYTHONPATH=. BEAM=beam6
while pgrep -f "queue7.sh" >/dev/null; do sleep 5; done
/usr/bin/python3 thickness.py beam6
CONE=45 RIGID_ANCHOR=1 /usr/bin/python3 beam_lbulk.py 0.3 0.5 0.01 1 corot bend,twist,stretch 10,1.5
/usr/bin/python3 beam_lbulk.py 1e-9 0.5 0.01 1 corot bend,twist,stretch
