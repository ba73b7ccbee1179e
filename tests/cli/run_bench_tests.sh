#!/usr/bin/env bash
# sph bench: the quick suite runs every case on 1 thread and on every core
# and writes its JSON (schema, machine, per case the figures); every figure
# is finite and positive. No timing thresholds: machines are shared.
set -u
sph=$1
. "$(dirname "$0")/harness.sh"
# the suite's folder goes under TMPDIR: this test's own
export TMPDIR="$work/tmp"
mkdir -p "$TMPDIR"

if "$sph" bench --quick --json "$work/bench.json" >"$work/out" 2>&1; then
  ok
else
  bad "sph bench --quick exited $?: $(cat "$work/out")"
fi
cat "$work/out"
if python3 - "$work/bench.json" <<'PY'; then
import json, math, sys
b = json.load(open(sys.argv[1]))
assert b["schema_version"] == 1 and b["suite"] == "quick", b
assert b["machine"]["cores"] >= 1 and b["machine"]["cpu"], b["machine"]
for key in ("triad_gb_per_s", "multiply_add_gflop_per_s"):
    v = b["machine"][key]
    assert 1 <= len(v) <= 2 and all(math.isfinite(x) and x > 0 for x in v), (key, v)
cases = b["cases"]
names = {c["name"] for c in cases}
assert len(names) == 9, names
threads = {c["threads"] for c in cases}
assert 1 in threads, threads
for c in cases:
    assert c["ok"], c
    for k in ("particles", "steps", "step_seconds", "setup_seconds", "first_step_seconds",
              "particle_steps_per_second_per_thread", "peak_rss_mb"):
        assert isinstance(c[k], (int, float)) and math.isfinite(c[k]) \
            and c[k] > 0, (c["name"], k, c[k])
    assert c["parts"] and all(math.isfinite(v) and v >= 0
                              for v in c["parts"].values()), c
    # the N-thread row's serial fraction (Karp-Flatt; noisy, may be < 0)
    assert c["threads"] == 1 or math.isfinite(c["serial_fraction"]), c
    if "vtp_seconds" in c:
        assert c["vtp_seconds"] > 0 and c["frame_seconds"] > 0, c
assert any("vtp_seconds" in c for c in cases)
PY
  ok
else
  bad "bench.json"
fi
"$sph" bench --bogus >/dev/null 2>&1
[ $? -eq 2 ] && ok || bad "an unknown option: exit not 2"
ls "$TMPDIR"/sph_bench_* >/dev/null 2>&1 && bad "temporary folder left" || ok
# a reader that stops reading (SIGPIPE) and an interrupt (SIGINT) end the
# suite with its folder removed and no case left running
"$sph" bench --quick | head -n 1 >/dev/null
ls "$TMPDIR"/sph_bench_* >/dev/null 2>&1 && bad "folder left after SIGPIPE" || ok
timeout -s INT 5 "$sph" bench --quick >/dev/null 2>&1
sleep 1
ls "$TMPDIR"/sph_bench_* >/dev/null 2>&1 && bad "folder left after SIGINT" || ok
pgrep -f "$sph bench --quick" >/dev/null &&
  bad "a case still running after SIGINT" || ok
# sph bench peer (the peer's column for every method, minutes: not run in
# full here): a wrong operand, --quick, an unknown method exit 2; an
# interrupt ends it with its header printed and no case left running
for args in "peers" "peer --quick" "peer --case nosuch"; do
  "$sph" bench $args >/dev/null 2>&1
  [ $? -eq 2 ] && ok || bad "sph bench $args: exit not 2"
done
timeout -s INT 5 "$sph" bench peer --case tl-jst >"$work/peer" 2>&1
sleep 1
grep -q "11x61x11 to t = 0.5 s" "$work/peer" && ok || bad "peer: $(cat "$work/peer")"
pgrep -f "$sph bench peer" >/dev/null &&
  bad "a peer case still running after SIGINT" || ok
echo "$pass passed, $fail failed"
[ $fail -eq 0 ]
