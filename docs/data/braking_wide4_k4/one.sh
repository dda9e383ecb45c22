for s in "$@"; do
  sed "s/^roughness_modes = 16/roughness_modes = 16\nseed = $s/" wide4.toml > w$s.toml
  /usr/bin/time -f "%e wall %U user" -o time$s.txt /work/main/.venv/bin/tribodem braking run --config w$s.toml --condition 5 --out p$s --no-progress > log$s.txt 2>&1
done
