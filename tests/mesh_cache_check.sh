#!/usr/bin/env bash
# tests/mesh_cache_check.sh -- owns the test of the mesh cache's key: a .geo that includes another file is meshed again
# when the included file changes (until 2026-11-29 the key held the main .geo's text only, and the stale mesh was
# used, exit 0). Usage: mesh_cache_check.sh <rbcontact executable> <source dir>
set -u
exe=$1
src=$2
d=$(mktemp -d "${TMPDIR:-/tmp}/rbc_meshcache.XXXXXX") || exit 2
trap 'rm -rf "$d"' EXIT
grep -v '^ *lc_slave *= *{' "$src/meshes/ring_on_block.geo" > "$d/main.geo"
sed -i '1i Include "sizes.geo";' "$d/main.geo"
ndofs() { # the report's ndofs of the FOM on main.geo, with its own cache directory
  "$exe" fom -options_file "$src/runs/ring_on_block.opts" -mesh_file "$d/main.geo" -mesh_cache_dir "$d/cache" -report "$d/r.json" > "$d/log" 2>&1 || { cat "$d/log"; exit 1; }
  /usr/bin/python3 -c "import json, sys; print(json.load(open(sys.argv[1]))['ndofs'])" "$d/r.json"
}
echo 'lc_slave = 0.025;' > "$d/sizes.geo"
a=$(ndofs)
echo 'lc_slave = 0.0125;' > "$d/sizes.geo"
b=$(ndofs)
echo "ndofs with lc_slave 0.025 in the included file: $a; after halving it: $b"
if [ "$a" = 8600 ] && [ "$b" -gt "$a" ]; then echo "ok: the edited included file gave a new mesh"; exit 0; fi
echo "FAIL: the mesh cache ignored the edited included file"
exit 1
