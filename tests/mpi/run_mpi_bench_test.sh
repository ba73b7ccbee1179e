#!/usr/bin/env bash
# sph bench --mpi --quick (issue 20): the tl-csph column at 202,771
# particles on one rank without a launcher and on 2 ranks under mpirun;
# the JSON holds the particle count, finite positive times and rates, and
# on 2 ranks the halo of docs/results.md (1,962 ghosts a rank, 12 doubles
# per ghost and step in 2 messages a rank: 47,088 values, 4 messages);
# --mpi with --case and the forking suite under mpirun are refused (exit
# 2). No timing thresholds: machines are shared.
set -u
sph=$1
# shellcheck source=mpi_common.sh
. "$(dirname "$0")/mpi_common.sh"

"$sph" bench --mpi --quick --json "$work/r1.json" || fail "1 rank: exit $?"
"${mpi[@]}" -np 2 "$sph" bench --mpi --quick --json "$work/r2.json" ||
  fail "2 ranks: exit $?"
/usr/bin/python3 - "$work/r1.json" "$work/r2.json" <<'PY' || fail "bench JSON"
import json, math, sys
for path, ranks in zip(sys.argv[1:], (1, 2)):
    b = json.load(open(path))
    assert b["schema_version"] == 1 and b["suite"] == "mpi-quick", b
    c, = b["cases"]
    assert c["ok"] and c["ranks"] == ranks and c["threads"] == 1, c
    assert c["particles"] == 202771 and c["steps"] == 10, c
    for k in ("setup_seconds", "first_step_seconds", "step_seconds",
              "particle_steps_per_second", "peak_rss_mb_per_rank"):
        assert math.isfinite(c[k]) and c[k] > 0, (k, c)
    if ranks == 1:
        assert c["halo_values_per_step"] == 0 and c["exchange_seconds"] == 0, c
    else:
        assert c["max_ghosts"] == 1962 and c["max_owned"] == 101386, c
        assert c["halo_values_per_step"] == 47088, c
        assert c["halo_messages_per_step"] == 4, c
        assert 0 < c["exchange_seconds"] < c["step_seconds"], c
PY
"$sph" bench --mpi --case x >"$work/log" 2>&1
[ $? -eq 2 ] && grep -q "strong (the default) or weak" "$work/log" || fail "--mpi --case x: $(cat "$work/log")"
"${mpi[@]}" -np 2 "$sph" bench --quick >"$work/log" 2>&1
[ $? -eq 2 ] && grep -q "only 'sph bench --mpi' runs" "$work/log" ||
  fail "bench under mpirun: $(cat "$work/log")"
echo "$fails failures"
[ $fails -eq 0 ]
