#!/bin/bash
# precompile.sh ROOT: compile ROOT's kernels natively for the CPU valgrind shows (haswell, no AVX-512)
NUMBA_CPU_NAME=haswell NUMBA_CPU_FEATURES="$(cat ${CG_DIR:-/tmp/rp}/vg_features)" PYTHONPATH=$1 \
  /work/main/.venv/bin/python /work/ab/rest/benchmarks/row_rest.py 64,1 0 -
