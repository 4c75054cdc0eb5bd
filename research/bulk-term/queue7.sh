#!/bin/bash
export OMP_NUM_THREADS=1 OPENBLAS_NUM_THREADS=1 BULK_TERM_DATA=data PYTHONPATH=. CONE=45 RIGID_ANCHOR=1
/usr/bin/python3 beam_lbulk.py 0.3 0.5 0.01 1 membrane bend,twist,stretch 10,1.5 | grep -v "^{"
for ba in 5 20; do /usr/bin/python3 beam_lbulk.py 0.3 0.5 0.01 1 corot bend $ba,1.5 | grep -v "^{" ; done
/usr/bin/python3 punch_lbulk.py 0.3 0.5 0.01 1 corot 10,1.5
