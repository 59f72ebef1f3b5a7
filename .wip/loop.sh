#!/bin/bash
cd /work/wt/h38p
for it in $(seq 1 15); do
  python3 /tmp/h38p/narrow.py apply
  /tmp/h38p/check.sh
  python3 /tmp/h38p/narrow.py parse /tmp/h38p/c[123].json > /tmp/h38p/parse.$it.txt
  tail -1 /tmp/h38p/parse.$it.txt
  if grep -q '^new 0 ' /tmp/h38p/parse.$it.txt; then echo DONE $it; break; fi
done
