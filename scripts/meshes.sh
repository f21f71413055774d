# Sourced by scripts/peers.sh and scripts/scaling.sh: `path_of NAME` prints the file of a
# benchmark mesh, from $SHARED (the shared `scenes` folder); `tetra` is generated once
# into $OUT by $RAYLAB.
path_of() {
  case "$1" in
    bunny) echo "$SHARED/bunny_69451.obj" ;;
    dragon202k) echo "$SHARED/dragon_vrip_res2.obj.gz" ;;
    dragon871k) echo "$SHARED/dragon_vrip.obj.gz" ;;
    tetra)
      # 4^11 = 4.2M triangles; generated once.
      [ -e "$OUT/tetra10.toml" ] || "$RAYLAB" gen tetra --size 10 -o "$OUT/tetra10.toml" >&2
      echo "$OUT/tetra10.toml" ;;
    *) echo "unknown mesh '$1' in MESHES (expected bunny, dragon202k, dragon871k, tetra)" >&2; exit 2 ;;
  esac
}
