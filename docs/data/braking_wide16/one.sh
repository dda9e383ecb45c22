# one.sh SEED...: run the given packings one after another
for s in "$@"; do
  sed "s/^roughness_modes = 64/roughness_modes = 64\nseed = $s/" wide16.toml > w$s.toml
  /usr/bin/time -f "%e wall %U user" -o time$s.txt /work/main/.venv/bin/tribodem braking run --config w$s.toml --condition 5 --out p$s --no-progress > log$s.txt 2>&1
done
