#!/usr/bin/env bash
# Behaviour guard for refactors (issue 22): runs a fixed list of 67 CLI commands from a
# checkout's root and records each one's exit code, stdout, stderr, and a hash of every file
# written (timings masked, tools/guard/hash.py). Compare two runs with tools/guard/compare.sh.
# Usage: tools/guard/run.sh REPO OUTDIR   (REPO's target/release/kinergy must be built;
# it writes a scratch folder REPO/guard-w; the Bandai commands need ../shared/data)
set -uo pipefail
REPO="$(cd "$1" && pwd)"; OUT="$(mkdir -p "$2" && cd "$2" && pwd)"; HERE="$(cd "$(dirname "$0")" && pwd)"
cd "$REPO"
K="$REPO/target/release/kinergy"
rm -rf guard-w "$OUT"; mkdir -p guard-w "$OUT"
W=guard-w
n=0
run() {
  n=$((n+1)); local id; id=$(printf "%02d" $n)
  echo "$*" > "$OUT/$id.cmd"
  "$K" "$@" > "$OUT/$id.out" 2> "$OUT/$id.err"
  echo $? > "$OUT/$id.rc"
}
C=data-synthetic/p01/r09.bvh
P=tests/data/params/synthetic-p01-r09-sc.json
R=tests/data/params/006_14-sc.json
run inspect $C --json
run inspect tests/data/006_14.bvh
run segment $C --json
run segment data-synthetic/p01 --manifest $W/seg.csv
run segment tests/data/006_14.bvh --arm left --select all
run convert $C --frames 7..87 -o $W/cap.bvh
run fit $C --model sa --per clip -o $W/sa.json
run fit $C --model sc --per clip -o $W/sc.json --json
run fit $C --model sd --per clip --budget 600 -o $W/sd.json
run fit data-synthetic/p01/r01.bvh data-synthetic/p01/r02.bvh data-synthetic/p01/r03.bvh --model sc --per person --budget 600 -o $W/p01.json
run fit data-synthetic/p01/r01.bvh data-synthetic/p01/r02.bvh data-synthetic/p01/r03.bvh data-synthetic/p01/r04.bvh --model sc --per person --field --budget 400 -o $W/field.json
run fit data-synthetic/p01/r05.bvh data-synthetic/p01/r06.bvh --segments $W/seg.csv --model sb --per clip --out-dir $W/fits --budget 300
run fit $C --model sc --per clip --budget 300 --refine 200 -o $W/ref.json
run compare data-synthetic/p01 --models sa,sc --optimizers svd --budget 200 -o $W/cmp
run compare data-synthetic/p01 data-synthetic/p02 --models sa,sc --per person --holdout 2 --budget 200 -o $W/hold
run synthesize --from $C --params $W/sc.json --frames auto --stop-at-reach -o $W/S_C.bvh --json
run synthesize --from $C --params $W/sa.json --frames auto --stop-at-reach -o $W/S_A.bvh
run synthesize $C --params $W/field.json --target 0.2,1.3,0.5 -o $W/sf.bvh --json
run synthesize $C --model sc --optimizer jt -o $W/sjt.bvh
run synthesize $C --target 1e155,0,0 -o $W/bad.bvh
run reach --target 0.3,1.2,0.5 -o $W/r1.bvh --json
run reach --target -0.4,1.0,0.6 --profile minimum-jerk -o $W/r2.bvh
run reach --target 0.2,0.15,0.6 --flexibility 3 -o $W/r3.bvh --json
run reach --target 0.1,1.2,1.4 --seed 3 -o $W/r4.bvh --json
run reach --target 0,1.2,5 -o $W/r5.bvh
run reach --target -0.3,1.3,0.45 --params $P -o $W/r6.bvh --json
run reach --target -0.3,1.6,0.4 --params $W/field.json -o $W/r7.bvh --json
run reach --target 0.3,1.3,0.45 --params $W/field.json --arm left -o $W/r8.bvh --json
run reach --target 0.3,1.1,0.5 --person tests/data/006_14.bvh --params $R -o $W/r9.bvh
run reach --target 0.3,1.1,0.5 --params nonexistent.json -o $W/r10.bvh
run plan --scene examples/bookshelf/scene.json --task relocate --object blue_book --to -0.22,1.49,0.50 -o $W/rel.bvh --json
cp "$OUT/$(printf %02d $n).out" $W/rel.json
run plan --scene examples/bookshelf/scene.json --task grasp --object blue_book -o $W/gr.bvh
run plan --scene examples/bookshelf/scene.json --task relocate --object blue_book --to -0.22,1.49,0.50 --params $P --seed 1 -o $W/relp.bvh --json
run plan --scene examples/bookshelf/scene.json --task grasp --object blue_book --params $W/field.json --seed 2 -o $W/grf.bvh --json
run plan --scene examples/bookshelf/scene.json --task grasp --object blue_book --params $W/field.json --arm left --seed 2 -o $W/grfl.bvh --json
run plan --scene examples/bookshelf/scene.json --target 0,1.2,9 -o $W/far.bvh
run style data-synthetic/p01/r05.bvh data-synthetic/p01/r06.bvh --params $W/p01.json --json
run style data-synthetic/p01/r05.bvh data-synthetic/p01/r07.bvh --params $W/field.json -o $W/sty
run style data-synthetic/p01/r05.bvh --params $W/field.json --arm left
run plot speed $W/cap.bvh $W/S_A.bvh $W/S_C.bvh --relative -o $W/speed.svg --csv $W/speed.csv
run animate $W/cap.bvh $W/S_A.bvh $W/S_C.bvh --view side --fps 15 --size 240x180 -o $W/ov.gif --strip $W/ov.png --strip-frames 4
run animate $W/rel.bvh --scene examples/bookshelf/scene.json --report $W/rel.json --view side --fps 10 --size 200x200 -o $W/rel.gif
run synth -o $W/syn --persons 1 --reaches 2
run synth -o $W/synp --persons 1 --reaches 2 --params $P
run synth -o $W/synf --persons 1 --reaches 2 --params $W/field.json
run synth -o $W/full
run fit data-synthetic/p01/r01.bvh --model sz -o $W/x.json
run fit nonexistent.bvh --model sa -o $W/x.json
run style $C --params $W/nothere.json
B=../shared/data/bandai-raise-left
mkdir -p $W/sty2
run style data-synthetic/p01/r05.bvh data-synthetic/p01/r07.bvh --params $W/p01.json -o $W/sty2
run style $B/normal_005.bvh --params $W/field.json --arm left --json
run fit $B/normal_001.bvh $B/normal_002.bvh $B/normal_003.bvh $B/normal_004.bvh --arm left --model sc --per person --field --budget 300 -o $W/lfield.json
run reach --target -0.3,1.3,0.45 --params $W/lfield.json -o $W/r11.bvh --json
run reach --target 0.3,1.5,0.35 --params $W/lfield.json -o $W/r12.bvh --json
run synthesize $B/normal_005.bvh --arm left --params $W/field.json -o $W/s5.bvh --json
run synthesize $B/normal_006.bvh --arm left --params $W/lfield.json -o $W/s6.bvh --json
run plan --scene examples/bookshelf/scene.json --task grasp --object blue_book --params $W/lfield.json --seed 2 -o $W/grl.bvh --json
run style $B/normal_006.bvh $B/normal_007.bvh --params $W/lfield.json --arm left --json
run compare -o $W/main
# The library protocol: shards, a resume, collect, the library summary, and a mixed collect.
run fit data-synthetic/p02 --model sa,sc --per clip --budget 200 --out-dir $W/lib --shard 1/2
run collect $W/lib
run fit data-synthetic/p02 --model sa,sc --per clip --budget 200 --out-dir $W/lib --shard 2/2
run fit data-synthetic/p02 --model sa,sc --per clip --budget 200 --out-dir $W/lib --shard 2/2 --resume
run collect $W/lib
run compare --library $W/lib -o $W/libcmp
run fit data-synthetic/p03 --model sa --per clip --budget 200 --out-dir $W/lib2 --json
run fit $C --model sa --per person --out-dir $W/lib3
python3 "$HERE/hash.py" guard-w > "$OUT/files.sha256"
