#!/bin/bash
export OMP_NUM_THREADS=1 OPENBLAS_NUM_THREADS=1 BULK_TERM_DATA=data PYTHONPATH=.
while pgrep -f "queue2.sh" >/dev/null; do sleep 5; done
r() { timeout 900 /usr/bin/python3 lanchor.py "$@" 2>&1 | grep -v "^   step"; }
# skin alone (no bulk at all), both capsules, this harness (5 steps)
r beam 0 1 0 1 0.01 2 bend,twist,stretch
r beam_membrane 0 1 0 1 0.01 2 bend,twist
# punch: below-thickness bulk + boundary anchor
for ba in 0.3 1; do for ca in 1.5 2; do r punch 0.9 0.5 $ba $ca 0.01 2; done; done
