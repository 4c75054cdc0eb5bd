#!/bin/bash
# beam runs through lanchor.py (Anderson mixing), one after the other
export OMP_NUM_THREADS=1 OPENBLAS_NUM_THREADS=1 BULK_TERM_DATA=data PYTHONPATH=.
r() { timeout 900 /usr/bin/python3 lanchor.py "$@" 2>&1 | grep -v "^   step"; }
r beam 0.9 0.5 0 1 0.2535 2 bend
r beam 0.1 0.5 0 1 0.01 2 bend
r beam 0.9 3 0 1 0.01 2 stretch
r beam_membrane 0.9 3 0 1 0.01 2 twist,stretch
r beam_membrane 1.2 1 0 1 0.01 2 bend,twist,stretch
r beam 1.2 1 0 1 0.01 2 stretch
