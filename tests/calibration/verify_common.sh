# Sourced by the verify_*.sh scripts (tests/calibration): what they share.

# random_bytes SEED: a stream of bytes fixed by SEED for `shuf --random-source` (hex text: any bytes will
# do). (`yes SEED` is no such stream: seeds a few seconds apart share their leading digits, and shuf drew
# the same picks from them.)
random_bytes() {
  local i
  for ((i = 0; i < 256; ++i)); do printf '%s %d' "$1" "$i" | sha256sum | cut -c1-64; done
}

# reproduced COMMITTED_STORE RERUN_STORE WORK HASH...: each rerun record must hold its committed record's
# measurements exactly (the clock, the host and the process aside); prints a line each and sets
# not_reproduced to how many did not.
reproduced() {
  local committed=$1 rerun=$2 work=$3 h
  local fields='^(key|status|angle_deg|angle_sd_deg|csa_percent|csa_sd_percent|steady|simulated_time_s|dt_s|particle_steps|granules|dt_margin_min|dt_lowered):'
  shift 3
  not_reproduced=0
  for h in "$@"; do
    if diff <(grep -E "$fields" "$committed/$h.yaml") <(grep -E "$fields" "$rerun/$h.yaml") > "$work/$h.diff"; then
      echo "ok   $h reproduced: $(grep -E '^(angle_deg|csa_percent):' "$rerun/$h.yaml" | tr '\n' ' ')"
    else
      echo "FAIL: $h not reproduced:"; cat "$work/$h.diff"; not_reproduced=$((not_reproduced + 1))
    fi
  done
}
