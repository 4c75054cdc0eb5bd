#!/bin/bash
# the rule fixed on the punch (aux-field bulk below h/2 + boundary anchor across the body) on the beams
export OMP_NUM_THREADS=1 OPENBLAS_NUM_THREADS=1 BULK_TERM_DATA=data PYTHONPATH=.
CONE=45 timeout 1200 /usr/bin/python3 beam_lbulk.py 0.3 0.5 0.01 1 corot bend,twist,stretch 10,1.5
CONE=45 timeout 1200 /usr/bin/python3 beam_lbulk.py 0.3 0.5 0.01 1 membrane bend,twist,stretch 10,1.5
