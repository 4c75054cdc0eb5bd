#!/bin/bash
export OMP_NUM_THREADS=1 OPENBLAS_NUM_THREADS=1 BULK_TERM_DATA=data PYTHONPATH=.
while pgrep -f "queue3.sh" >/dev/null; do sleep 5; done
r() { timeout 900 /usr/bin/python3 lanchor.py "$@" 2>&1 | grep -v "^   step"; }
for ba in 5 20; do r punch 0.9 0.5 $ba 1.5 0.01 2; done
r beam 0.9 0.25 0 1 0.01 1 bend
r beam 0.9 0.5 10 1.5 0.01 2 bend
