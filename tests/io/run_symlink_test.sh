#!/usr/bin/env bash
# Output files never follow a symbolic link (issue 36 item 1): a link
# planted in the output folder under the name of a file sph writes (the
# lock, energy.csv, probes.csv, a .vtp, the .pvd, summary.json and its
# .part, scene_used.yaml, a PNG frame, the checkpoint), or of the CSV
# tables a --resume continues in place, is refused with a message naming
# the file, and the link's target is left unchanged. A FIFO or a huge file
# given as the checkpoint is refused without reading it.
set -u
sph=$1
src=$2
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
fails=0
fail() { echo "FAIL: $*"; fails=$((fails + 1)); }
scene=$src/scenes/twisting_column.yaml
args=(--threads 1 --quiet --set 'bodies.0.particles.count=[5,25,5]'
  --set time.end=0.3 --set output.checkpoint_every=0.05
  --set 'output.png={width: 64, height: 48}')

n=0
# planted CODE NAME: a run whose folder holds NAME, a link to a file of
# ours, must refuse it with exit CODE (2: at the start, before anything is
# written: a name the run writes that is no regular file of the folder's
# manifest, issue 36 item 4), naming it, and leave the link's target as it
# was
planted() {
  local want=$1 name=$2
  shift 2
  n=$((n + 1))
  local out=$work/o$n target=$work/v$n
  mkdir -p "$out/$(dirname "$name")"
  if [ "$name" = frames ]; then # a folder: nothing may appear in it
    mkdir "$target"
    ln -s "$target" "$out/$name"
    "$sph" run "$scene" --out "$out" "${args[@]}" "$@" >"$work/log" 2>&1
    local rc=$?
    [ $rc -eq "$want" ] || fail "$name: exit $rc, expected $want: $(tail -2 "$work/log")"
    grep -q "frames" "$work/log" || fail "$name: the message does not name it: $(tail -2 "$work/log")"
    [ -z "$(ls "$target")" ] || fail "$name: written into the link's target: $(ls "$target" | head -3)"
    return
  fi
  printf 'precious %d\n' $n >"$target"
  cp "$target" "$work/keep"
  ln -s "$target" "$out/$name"
  "$sph" run "$scene" --out "$out" "${args[@]}" "$@" >"$work/log" 2>&1
  local rc=$?
  [ $rc -eq "$want" ] || fail "$name: exit $rc, expected $want: $(tail -2 "$work/log")"
  grep -qi -e "$(basename "$name")" -e "results of an earlier run" -e "symbolic link" "$work/log" || fail "$name: the message does not name it: $(tail -2 "$work/log")"
  cmp -s "$target" "$work/keep" || fail "$name: the link's target was written"
}

planted 2 .sph.lock
planted 2 energy.csv
planted 2 probes.csv
planted 2 twisting_column_0000.vtp
planted 2 twisting_column_0003.vtp
planted 2 twisting_column.pvd
planted 2 twisting_column.pvd.part
planted 2 summary.json
planted 2 summary.json.part
planted 2 scene_used.yaml
planted 2 scene_used.yaml.part
planted 2 frames/twisting_column_0000.png
planted 2 frames/twisting_column_0002.png.part
planted 2 checkpoint.sphc
planted 3 frames
planted 2 checkpoint.sphc.part
planted 2 checkpoint.prev.sphc

# a stopped run's CSV tables are continued in place by --resume: a link
# put in their place is refused, its target untouched
"$sph" run "$scene" --out "$work/stopped" "${args[@]}" --set output.png=false \
  --set time.end=1 >"$work/log" 2>&1 &
pid=$!
for _ in $(seq 500); do
  [ -f "$work/stopped/checkpoint.prev.sphc" ] && break
  sleep 0.02
done
kill -TERM $pid
wait $pid
[ -f "$work/stopped/checkpoint.sphc" ] || fail "the stopped run left no checkpoint: $(tail -2 "$work/log")"
for name in probes.csv energy.csv; do
  cp -a "$work/stopped" "$work/resume_$name"
  target=$work/t_$name
  mv "$work/resume_$name/$name" "$target"
  cp "$target" "$work/keep"
  ln -s "$target" "$work/resume_$name/$name"
  "$sph" run "$scene" --resume "$work/resume_$name" "${args[@]}" --set output.png=false \
    --set time.end=1 >"$work/log" 2>&1
  rc=$?
  [ $rc -eq 2 ] || fail "resume with $name a link: exit $rc, expected 2: $(tail -2 "$work/log")"
  grep -q "$name" "$work/log" || fail "resume with $name a link: the message does not name it: $(tail -2 "$work/log")"
  cmp -s "$target" "$work/keep" || fail "resume with $name a link: its target was written"
done

# the checkpoint read by --resume (issue 36 item 8): a FIFO is refused, not
# waited on
cp -a "$work/stopped" "$work/fifo"
rm "$work/fifo/checkpoint.sphc" "$work/fifo/checkpoint.prev.sphc"
mkfifo "$work/fifo/checkpoint.sphc"
timeout 20 "$sph" run "$scene" --resume "$work/fifo" "${args[@]}" --set output.png=false \
  --set time.end=1 >"$work/log" 2>&1
rc=$?
[ $rc -eq 2 ] || fail "a FIFO as the checkpoint: exit $rc, expected 2: $(tail -2 "$work/log")"
grep -q "not a regular file" "$work/log" || fail "a FIFO as the checkpoint: $(tail -2 "$work/log")"

# a checkpoint far larger than this run's can be (a sparse 50 GB file
# behind a valid header) is refused from its size, not read whole
cp -a "$work/stopped" "$work/huge"
rm "$work/huge/checkpoint.prev.sphc"
truncate -s 50G "$work/huge/checkpoint.sphc"
timeout 20 "$sph" run "$scene" --resume "$work/huge" "${args[@]}" --set output.png=false \
  --set time.end=1 >"$work/log" 2>&1
rc=$?
[ $rc -eq 2 ] || fail "a 50 GB checkpoint: exit $rc, expected 2: $(tail -2 "$work/log")"
grep -q "53687091200 bytes, a checkpoint of this run holds at most" "$work/log" ||
  fail "a 50 GB checkpoint: $(tail -2 "$work/log")"

echo "$((n + 4)) cases, $fails failures"
[ $fails -eq 0 ]
