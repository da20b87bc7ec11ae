#!/usr/bin/env bash
# Compares two runs of tools/guard/run.sh: compare.sh BASE NEW. Prints the commands whose exit
# code, stdout, stderr or output files differ (lines matching tools/guard/volatile, timings,
# are ignored); "guard: identical" and exit 0 when none do.
B="$1"; N="$2"; bad=0; V="$(cd "$(dirname "$0")" && pwd)/volatile"
for f in "$B"/*.cmd; do
  id=$(basename "$f" .cmd)
  for k in rc out err; do
    if ! diff -q <(grep -vEf $V "$B/$id.$k" 2>/dev/null) <(grep -vEf $V "$N/$id.$k" 2>/dev/null) >/dev/null; then
      echo "DIFF $id.$k: $(cat $f)"; bad=1
    fi
  done
done
if ! diff <(grep -vEf $V "$B/files.sha256") <(grep -vEf $V "$N/files.sha256"); then echo "DIFF files"; bad=1; fi
[ $bad = 0 ] && echo "guard: identical"
exit $bad
