# Sourced by the verify_*.sh scripts (tests/calibration): random_bytes SEED prints a stream of bytes fixed by SEED for
# `shuf --random-source` (hex text: any bytes will do). (`yes SEED` is no such stream: seeds a few seconds apart share their leading
# digits, and shuf drew the same picks from them.)
random_bytes() {
  local i
  for ((i = 0; i < 256; ++i)); do printf '%s %d' "$1" "$i" | sha256sum | cut -c1-64; done
}
