#!/bin/bash
# the rule fixed on the punch (below-thickness rigid-fit bulk + boundary anchor) checked on the beams
export OMP_NUM_THREADS=1 OPENBLAS_NUM_THREADS=1 BULK_TERM_DATA=data PYTHONPATH=.
r() { timeout 900 /usr/bin/python3 lanchor.py "$@" 2>&1 | grep -v "^   step"; }
r beam 0.9 0.5 20 1.5 0.01 2 bend,twist,stretch
r beam_membrane 0.9 0.5 20 1.5 0.01 2 bend,twist,stretch
