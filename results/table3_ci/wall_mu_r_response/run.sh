#!/bin/bash
seed=$1
for m in r1e-4 r1e-3 r1e-2 r0.033 r0.1 r0.2; do
  ./granucal-r3 simulate drum_walls.yaml --set lambda=32768 --set slice_depth=0.03 --set rpm=116 --set max_time=4 --set seed=$seed --set wall=$m --out out_${m}_s$seed > ${m}_s$seed.json 2> ${m}_s$seed.log
done
