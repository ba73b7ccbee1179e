# Shared by the cli test scripts (sourced): a temporary folder $work removed
# on exit, and the pass/fail counters with ok and bad MESSAGE.
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
pass=0
fail=0
ok() { pass=$((pass + 1)); }
bad() { fail=$((fail + 1)); echo "FAIL: $*"; }
