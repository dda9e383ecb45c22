for s in 0 1 2 3 4; do
  sed "s/^roughness_modes = 16/roughness_modes = 16\nseed = $s/" wide4.toml > w$s.toml
  /usr/bin/time -f "%e wall %U user" -o time$s.txt /work/main/.venv/bin/tribodem braking run --config w$s.toml --condition 5 --out p$s > log$s.txt 2>&1
done
