#!/bin/bash
# cgrun.sh ROOT TAG N,K REPEATS [extra args]
root=$1; tag=$2; nk=$3; reps=$4; shift 4
PYTHONPATH=$root valgrind --tool=callgrind --trace-children=yes --instr-atstart=no --collect-atstart=no \
  --dump-instr=yes --callgrind-out-file=${CG_DIR:-/tmp/rp}/cg.$tag.%p \
  /work/main/.venv/bin/python /work/ab/rest/benchmarks/row_rest.py $nk $reps ${CG_DIR:-/tmp/rp}/cgctl.so --map ${CG_DIR:-/tmp/rp}/map.$tag "$@" > ${CG_DIR:-/tmp/rp}/log.$tag 2>&1
