#!/bin/sh
# Hostile paths and inputs given to the calf commands, one case per run:
#   hostile_paths.sh CASE BIN_DIR WORK_DIR CAPTURE_SET SOURCE_DIR
# Each case builds its paths under WORK_DIR (emptied first), runs one calf command with its
# stdout and stderr passed through, and exits with that command's status, so calf_add_cli_test
# checks the one line and the status. A broken post-condition (a FIFO replaced, an input
# overwritten, a temporary file left) prints a second stderr line and exits 99, which fails the
# test whatever it expected.
set -u
name=$1
bin=$2
work=$3
set_dir=$4
src=$5
rm -rf "$work"
mkdir -p "$work"
broken() {
  echo "$name: post-condition broken: $*" >&2
  echo "(second line, so that the test fails)" >&2
  exit 99
}
no_temp_files() {
  if ls -a "$1" | grep -q '\.tmp-'; then broken "a temporary file was left in $1"; fi
}
first_image=view000_frame00000.exr
second_image=view000_frame00001.exr

case $name in
# ---- inputs that are not regular files: refused at once, never opened (no hang on a FIFO) ----
info-fifo)
  mkfifo "$work/f.calf"
  timeout 20 "$bin/calf-info" "$work/f.calf"
  rc=$?
  ;;
verify-fifo)
  mkfifo "$work/f.calf"
  timeout 20 "$bin/calf-verify" "$work/f.calf"
  rc=$?
  ;;
play-fifo)
  mkfifo "$work/f.calf"
  timeout 20 "$bin/calf-play" "$work/f.calf" --headless --eye-path "$set_dir/../gt/eye_path.json"
  rc=$?
  ;;
encode-image-directory)
  cp -r "$set_dir" "$work/set"
  rm "$work/set/$second_image"
  mkdir "$work/set/$second_image"
  timeout 60 "$bin/calf-encode" "$work/set" -o "$work/c.calf" --quiet
  rc=$?
  [ -e "$work/c.calf" ] && broken "an output was written"
  ;;
encode-image-fifo)
  cp -r "$set_dir" "$work/set"
  rm "$work/set/$second_image"
  mkfifo "$work/set/$second_image"
  timeout 60 "$bin/calf-encode" "$work/set" -o "$work/c.calf" --quiet
  rc=$?
  [ -e "$work/c.calf" ] && broken "an output was written"
  ;;
encode-png-named-exr)
  cp -r "$set_dir" "$work/set"
  # A damaged PNG (its IHDR checksum overwritten) is what made libpng print its own stderr line.
  cp "$src/docs/bench/interior_psnr_bytes.png" "$work/set/$first_image"
  printf '\377\377\377\377' | dd of="$work/set/$first_image" bs=1 seek=29 conv=notrunc 2>/dev/null
  timeout 60 "$bin/calf-encode" "$work/set" -o "$work/c.calf" --quiet
  rc=$?
  ;;
# ---- outputs that are not regular files: refused, left as they are ----
encode-onto-fifo)
  mkfifo "$work/f.calf"
  timeout 60 "$bin/calf-encode" "$set_dir" -o "$work/f.calf" --quiet
  rc=$?
  [ -p "$work/f.calf" ] || broken "the FIFO was replaced"
  no_temp_files "$work"
  ;;
encode-onto-device)
  # A character device (/dev/null's numbers) where root may make one, else a FIFO.
  mknod "$work/n" c 1 3 2>/dev/null || mkfifo "$work/n"
  timeout 60 "$bin/calf-encode" "$set_dir" -o "$work/n" --quiet
  rc=$?
  [ -c "$work/n" ] || [ -p "$work/n" ] || broken "the device node was replaced"
  no_temp_files "$work"
  ;;
encode-onto-directory)
  mkdir "$work/d.calf"
  timeout 60 "$bin/calf-encode" "$set_dir" -o "$work/d.calf" --quiet
  rc=$?
  [ -d "$work/d.calf" ] || broken "the directory was replaced"
  no_temp_files "$work"
  ;;
encode-onto-symlink)
  echo keep >"$work/target"
  ln -s target "$work/l.calf"
  timeout 60 "$bin/calf-encode" "$set_dir" -o "$work/l.calf" --quiet
  rc=$?
  [ -L "$work/l.calf" ] || broken "the symbolic link was replaced"
  [ "$(cat "$work/target")" = keep ] || broken "the link's target was written"
  no_temp_files "$work"
  ;;
capture-onto-fifo)
  # calf-capture's outputs go through the same rule: its manifest.json is a FIFO here.
  mkdir "$work/out"
  mkfifo "$work/out/manifest.json"
  timeout 60 "$bin/calf-capture" --scene interior --face-size 8 --frames 1 --rig list:0,1.6,0 \
    --quiet --out "$work/out"
  rc=$?
  [ -p "$work/out/manifest.json" ] || broken "the FIFO was replaced"
  no_temp_files "$work/out"
  ;;
play-sheet-onto-fifo)
  mkfifo "$work/sheet.png"
  timeout 60 "$bin/calf-play" "$set_dir/../clip.calf" --headless --compare "$set_dir/../gt" \
    --contact-sheet "$work/sheet.png" >/dev/null
  rc=$?
  [ -p "$work/sheet.png" ] || broken "the FIFO was replaced"
  no_temp_files "$work"
  ;;
# ---- an output that is an input ----
encode-onto-manifest | encode-onto-image | encode-onto-set)
  cp -r "$set_dir" "$work/set"
  case $name in
  encode-onto-manifest) target="$work/set/manifest.json" ;;
  encode-onto-image) target="$work/set/$first_image" ;;
  *) target="$work/set" ;;
  esac
  timeout 60 "$bin/calf-encode" "$work/set" -o "$target" --quiet
  rc=$?
  for f in manifest.json "$first_image"; do
    cmp -s "$work/set/$f" "$set_dir/$f" || broken "the input $f was changed"
  done
  no_temp_files "$work/set"
  ;;
# The analysis file is an input of every shard and of the merge.
shard-onto-analysis | merge-onto-analysis)
  "$bin/calf-encode" "$set_dir" --analysis-only -o "$work/a.calf" --quiet || broken "analysis failed"
  cp "$work/a.calf" "$work/a.orig"
  if [ $name = shard-onto-analysis ]; then
    timeout 60 "$bin/calf-encode" "$set_dir" --analysis "$work/a.calf" --views 0 -o "$work/a.calf" \
      --quiet
    rc=$?
  else
    # One shard of every view, so that nothing but the output check can stop the merge.
    views=$(ls "$set_dir" | grep -c '_frame00000\.')
    "$bin/calf-encode" "$set_dir" --analysis "$work/a.calf" --views "0-$((views - 1))" \
      -o "$work/s0.calf" --quiet || broken "shard failed"
    timeout 60 "$bin/calf-merge" --analysis "$work/a.calf" "$work/s0.calf" -o "$work/a.calf" -q
    rc=$?
  fi
  cmp -s "$work/a.calf" "$work/a.orig" || broken "the analysis file was changed"
  no_temp_files "$work"
  ;;
# calf-export's side files (OUT.bin, OUT.mtl, OUT_atlas.png, OUT_texture<n>.png) are outputs too.
export-onto-bin | export-onto-mtl | export-onto-atlas | export-onto-texture)
  case $name in
  export-onto-bin) clip=c.bin out=c.gltf from=mesh/textured_zstd.calf ;;
  export-onto-mtl) clip=d.mtl out=d.obj from=mesh/textured_zstd.calf ;;
  export-onto-atlas) clip=e_atlas.png out=e.obj from=tiles/bc7_zstd.calf ;;
  *) clip=f_texture0.png out=f.obj from=mesh/textured_zstd.calf ;;
  esac
  cp "$src/tests/conformance/$from" "$work/$clip"
  timeout 60 "$bin/calf-export" "$work/$clip" -o "$work/$out" -q
  rc=$?
  cmp -s "$work/$clip" "$src/tests/conformance/$from" || broken "the input clip was changed"
  [ -e "$work/$out" ] && broken "an output was written"
  no_temp_files "$work"
  ;;
# ---- a scene the mesh track refuses is refused by --visible-set too, in one line ----
visible-set-far-vertex)
  mkdir -p "$work/scene"
  z='\000\000\000\000'
  one='\000\000\200\077'
  big='\346\261\141\177'  # 3e38
  printf "$z$z$z$big$z$z$z$one$z"'\000\000\000\000\001\000\000\000\002\000\000\000' \
    >"$work/scene/scene.bin"
  printf "$one$z$z$z$z$one$z$z$z$z$one"'\000\000\100\300' >>"$work/scene/scene.bin"
  cat >"$work/scene/scene.json" <<'JSON'
{"format": "calf-scene", "version": 1, "name": "far", "fps": 24, "frame_count": 1,
 "view_region": {"min": [0, 1, 0], "max": [1, 2, 1]},
 "buffers": [{"uri": "scene.bin", "byte_length": 96}],
 "materials": [{"base_color": [0.5, 0.25, 1]}],
 "meshes": [{"positions": {"buffer": 0, "offset": 0, "count": 3},
             "triangles": {"buffer": 0, "offset": 36, "count": 1}}],
 "objects": [{"mesh": 0, "material": 0, "transforms": {"buffer": 0, "offset": 48, "count": 1}}]}
JSON
  timeout 60 "$bin/calf-encode" --mode mesh --visible-set --visibility-face-size 16 \
    "$work/scene" -o "$work/v.calf"
  rc=$?
  [ -e "$work/v.calf" ] && broken "an output was written"
  no_temp_files "$work"
  ;;
# ---- temporary files ----
stale-temp)
  # Left by dead processes of this host (a pid above any pid_max): removed by the next writer.
  # One of a live process (this shell) and one of another host stay.
  host=$(uname -n)
  echo partial >"$work/c.calf.tmp-$host-999999999-0"
  echo partial >"$work/old.calf.tmp-$host-999999998-3"
  echo partial >"$work/c.calf.tmp-$host-$$-0"
  echo partial >"$work/c.calf.tmp-elsewhere.invalid-999999999-0"
  timeout 120 "$bin/calf-encode" "$set_dir" -o "$work/c.calf" --quiet
  rc=$?
  [ -e "$work/c.calf.tmp-$host-999999999-0" ] && broken "a stale temporary file stayed"
  [ -e "$work/old.calf.tmp-$host-999999998-3" ] && broken "a stale temporary file stayed"
  [ -e "$work/c.calf.tmp-$host-$$-0" ] || broken "a live process's temporary file was removed"
  [ -e "$work/c.calf.tmp-elsewhere.invalid-999999999-0" ] || broken "another host's was removed"
  [ -f "$work/c.calf" ] || broken "no output"
  echo "stale temporary files removed"
  ;;
encode-sigterm | encode-sigint | encode-sighup)
  sig=$(echo "$name" | sed 's/encode-sig//' | tr a-z A-Z)
  # A background job of a non-interactive shell starts with SIGINT ignored (and calf keeps an
  # ignored signal ignored): env gives it the default action back.
  env --default-signal=INT,HUP,TERM "$bin/calf-encode" "$set_dir" -o "$work/c.calf" --quiet \
    --threads 1 --color-format bc7 --supercompression lzma2 &
  pid=$!
  # The container writer makes its temporary file before the first view is coded.
  i=0
  while [ $i -lt 3000 ] && ! ls -a "$work" | grep -q '\.tmp-'; do
    sleep 0.01
    i=$((i + 1))
  done
  ls -a "$work" | grep -q '\.tmp-' || broken "no temporary file appeared"
  kill -s "$sig" $pid
  wait $pid
  rc=$?
  [ $rc -gt 128 ] || broken "calf-encode was not ended by SIG$sig (exit status $rc)"
  no_temp_files "$work"
  [ -e "$work/c.calf" ] && broken "an output was written"
  echo "SIG$sig: exit status $rc, no temporary file left"
  rc=0
  ;;
# ---- terminal escapes in metadata ----
info-escapes)
  cp -r "$set_dir" "$work/set"
  sed 's/"scene": *"[^"]*"/"scene": "\\u001b]0;owned\\u0007\\u001b[31mred\\u009b"/' \
    "$set_dir/manifest.json" >"$work/set/manifest.json"
  grep -q 'u001b' "$work/set/manifest.json" || broken "the manifest has no scene field to edit"
  "$bin/calf-encode" "$work/set" -o "$work/c.calf" --quiet || broken "encode failed"
  "$bin/calf-info" "$work/c.calf" >"$work/info.txt"
  rc=$?
  esc=$(printf '\033')
  bel=$(printf '\007')
  if grep -q "[$esc$bel]" "$work/info.txt"; then broken "raw control bytes printed"; fi
  grep source_scene "$work/info.txt"
  ;;
*)
  echo "hostile_paths.sh: unknown case $name" >&2
  exit 98
  ;;
esac
exit $rc
