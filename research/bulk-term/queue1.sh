#!/bin/bash
# the beam runs of the local-thickness study, one after the other (one core)
export OMP_NUM_THREADS=1 OPENBLAS_NUM_THREADS=1 BULK_TERM_DATA=data PYTHONPATH=.
/usr/bin/python3 lrigid.py beam 1.2 1 0.01 2 bend,twist > logs_beam_rigid_ch1_corot.txt 2>&1
/usr/bin/python3 lrigid.py beam 0.9 0.5 0.01 2 bend,twist > logs_beam_rigid_ch05_corot.txt 2>&1
/usr/bin/python3 lrigid.py beam_membrane 0.9 3 0.01 2 bend > logs_beam_rigid_rule_membrane.txt 2>&1
