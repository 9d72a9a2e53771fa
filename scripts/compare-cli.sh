#!/usr/bin/env bash
# Byte-for-byte comparison of the command line's outputs between two `pdeshape` binaries, to
# show that a refactor changes nothing a user can see.
#
#   scripts/compare-cli.sh BEFORE_BIN AFTER_BIN
#
# Runs a fixed list of invocations (every subcommand but `serve`, on the bundled examples, at
# small grid sizes, plus error cases) with each binary in a fresh copy of the same tree, capturing
# stdout, stderr and the exit status of each and every file written, then compares the two
# trees. Prints one line per case, `NAME: same` or `NAME: DIFFERS: <what>`, and last
# `N passed, N failed`; exits 1 if anything differs, 2 on bad usage or a broken set-up.
# `scripts/compare-cli.sh B B` (one binary against itself) must report everything same.
#
# Layout: everything lives in one temporary root. `template/` holds a copy of examples/ (the
# animations cut to 4 frames) and fixtures/ (bad design files, and meshes and STEP/IGES files
# written once by BEFORE_BIN, so that `fit` and `roundtrip` read the same input under both
# binaries). For each binary the template is copied to `run/` (so both see the same absolute
# paths and nothing in the outputs depends on which tree ran), the binary is put first on PATH
# as `pdeshape` (so argv[0], and with it clap's usage lines, is the same), every case runs with
# `run/` as its working directory and relative paths, writing its files into out/CASE/ and its
# stdout, stderr and status into res/CASE.{stdout,stderr,status}; then run/ is renamed to
# before/ or after/. Each case is limited to 300 s (`timeout`; status 124 then).
#
# Determinism. Every run gets a clean environment (env -i) with:
#   SOURCE_DATE_EPOCH=0        the timestamp of `spline`'s IGES files (spline.rs)
#   RAYON_NUM_THREADS=2        the pool size (quadrature levels are split per worker)
#   PDESHAPE_MAX_MEMORY=1 GiB  the memory budget is min(4 GiB, MemAvailable/2, this), so refusals
#                              and their messages do not depend on the machine's free memory
#   TZ=UTC LC_ALL=C NO_COLOR=1 HOME=<root>/home, PATH=<binary dir>:$PATH (PDESHAPE_CCX passed on
#                              if set, for `shell`)
# `optimize` is given --threads explicitly (its default is the number of cores).
#
# Normalisation (sed, on both trees, before comparing) of what varies from run to run of the
# same binary, and nothing else (found by running one binary against itself):
#   N1 stderr of `surface/blend --timings`: every "..._ms":NUMBER becomes "..._ms":<ms>.
#   N2 stdout of `curve`: the wall time, `steps: ... in <s> s` and
#      `interpolating curve: ..., N force updates, <s> s`.
#   N3 stdout of `fit`: `... patches (...) in <ms> ms; Hausdorff ...`.
#   N4 `fit --json` files: the numbers of the "timings_ms" object.
#   N5 STEP files written by `surface` (out/surface_*/*.step|stp): the time in FILE_NAME.
#      Binaries from before the one CAD export (`cad::export_design`) stamp the wall-clock time
#      and do not read SOURCE_DATE_EPOCH; today's do, as `spline`'s IGES always did (not
#      normalised). The normalisation keeps such binaries comparable.
#   N6 IGES files written by `surface` (out/surface_*/*.igs|iges): the two 15HYYYYMMDD.HHMMSS
#      dates of the global section, replaced by a string of the same length (fixed columns).
#   N7 `shell` (only run when CalculiX is there): the `time: meshing ... s` line and the numbers
#      of the JSON "seconds" object.
# Nothing else is touched: PNG, GLB, GIF, STL, PLY and every other file is compared as written.
#
# KEEP=1 keeps the temporary root (its path is printed) to inspect a difference, e.g.
# `diff -r "$root"/before/out/CASE "$root"/after/out/CASE`.
set -uo pipefail

usage() {
    echo "usage: $0 BEFORE_BIN AFTER_BIN" >&2
    exit 2
}
[ $# -eq 2 ] || usage
for b in "$1" "$2"; do
    if [ ! -f "$b" ] || [ ! -x "$b" ]; then
        echo "$0: $b: not an executable file" >&2
        exit 2
    fi
done
before_bin="$(realpath "$1")"
after_bin="$(realpath "$2")"
repo="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
root="$(mktemp -d "${TMPDIR:-/tmp}/compare-cli.XXXXXX")"
cleanup() {
    if [ -n "${KEEP:-}" ]; then
        echo "# kept $root" >&2
    else
        rm -rf "$root"
    fi
}
trap cleanup EXIT
mkdir -p "$root/home"

# CalculiX for the `shell` cases: PDESHAPE_CCX if set, else `ccx` on the PATH.
ccx_program="${PDESHAPE_CCX:-ccx}"
have_ccx=0
if command -v "$ccx_program" >/dev/null 2>&1; then
    have_ccx=1
fi

base_env=(
    SOURCE_DATE_EPOCH=0
    RAYON_NUM_THREADS=2
    PDESHAPE_MAX_MEMORY=1073741824
    TZ=UTC
    LC_ALL=C
    NO_COLOR=1
    HOME="$root/home"
)
if [ -n "${PDESHAPE_CCX:-}" ]; then
    case "$PDESHAPE_CCX" in
        */*) base_env+=(PDESHAPE_CCX="$(realpath "$PDESHAPE_CCX")") ;;  # cases run elsewhere
        *) base_env+=(PDESHAPE_CCX="$PDESHAPE_CCX") ;;
    esac
fi

bindir=""     # set per binary: the directory holding the `pdeshape` link
names=()      # the cases, in order (the same list for both binaries)

# c NAME [VAR=VALUE ...] ARGS...: runs `pdeshape ARGS...` in the current tree (the working
# directory), with VAR=VALUE added to the environment; `@/` in an argument stands for out/NAME/.
c() {
    local name="$1"
    shift
    local extra=() args=() a
    while [ $# -gt 0 ] && [[ "$1" =~ ^[A-Z_][A-Z0-9_]*= ]]; do
        extra+=("$1")
        shift
    done
    for a in "$@"; do
        args+=("${a//@\//out/$name/}")
    done
    mkdir -p "out/$name"
    env -i "${base_env[@]}" PATH="$bindir:$PATH" "${extra[@]}" \
        timeout 300 pdeshape "${args[@]}" \
        </dev/null >"res/$name.stdout" 2>"res/$name.stderr"
    echo "$?" >"res/$name.status"
    names+=("$name")
}

# seed NAME SOURCE FILE MODE: puts a copy of SOURCE at out/NAME/FILE with MODE before case NAME.
seed() {
    mkdir -p "out/$1"
    cp "$2" "out/$1/$3"
    chmod "$4" "out/$1/$3"
}

# skip NAME WHY: a note instead of a case (printed before the totals).
skip() {
    echo "$1: skipped ($2)" >>"$root/skipped-$label"
}

# The cases. Grids are small (16 × 32 unless the case is about the grid), pictures small.
cases() {
    # --- meta
    c help --help
    c version --version
    c help_surface help surface
    c help_animate animate --help
    c schema schema

    # --- surface: every output format, the flags, and every example
    local g=(--nu 16 --nv 32)
    c surface_cup_obj surface examples/cup.toml -o @/cup.obj "${g[@]}" --picture @/cup.png
    c surface_cup_stl surface examples/cup.toml -o @/cup.stl "${g[@]}"
    c surface_cup_ply surface examples/cup.toml -o @/cup.ply "${g[@]}"
    c surface_cup_glb surface examples/cup.toml -o @/cup.glb "${g[@]}"
    c surface_cup_csv surface examples/cup.toml -o @/cup.csv --nu 8 --nv 12
    c surface_cup_step surface examples/cup.toml -o @/cup.step
    c surface_cup_stp_in surface examples/cup.toml -o @/cup.stp --units in
    c surface_cup_igs surface examples/cup.toml -o @/cup.igs
    c surface_cup_iges_tol surface examples/cup.toml -o @/cup.iges --tolerance 1e-3 --units m
    c surface_wine_step surface examples/wine_glass.toml -o @/wine.step --tolerance 1e-3
    c surface_stdout_csv surface examples/cup.toml -o - --format csv --nu 4 --nv 6
    c surface_stdout_obj surface examples/water_glass.toml -o - --format obj --nu 6 --nv 8
    c surface_noext_ply surface examples/cup.toml -o @/cup --format ply "${g[@]}"
    c surface_yup_scale surface examples/wine_glass.toml -o @/wine.obj "${g[@]}" --up y --scale 1000
    c surface_yup_stl surface examples/wine_glass.toml -o @/wine.stl "${g[@]}" --up y
    c surface_separate surface examples/klein_bottle_patches.toml -o @/klein.ply "${g[@]}" --separate-patches
    c surface_separate_glb surface examples/teacup.toml -o @/teacup.glb "${g[@]}" --separate-patches
    c surface_set surface examples/swirl_port_params.toml -o @/port.obj "${g[@]}" --set twist=0 --set theta=0.3 --set s=1.2
    c surface_time surface examples/anim/ventricle.toml -o @/v.stl "${g[@]}" --time 0.4
    c surface_morph_time surface examples/anim/glass_morph.toml -o @/g.obj "${g[@]}" --time 1
    c surface_picture_gauss surface examples/wine_glass.toml -o @/w.glb "${g[@]}" --picture @/w.png --color gauss
    c surface_picture_mean surface examples/cup.toml -o @/c.csv --nu 6 --nv 8 --picture @/c.png --color mean
    c surface_timings surface examples/cup.toml -o @/cup.glb "${g[@]}" --timings
    c surface_timings_obj surface examples/yoghurt.toml -o @/y.obj "${g[@]}" --timings
    c surface_quiet -q surface examples/cup.toml -o @/cup.obj "${g[@]}" --picture @/cup.png
    c surface_default_grid surface examples/laplace_blend.toml -o @/lb.stl
    local f b ext exts=(obj stl ply glb csv) k=0
    for f in examples/*.toml examples/spline/*.toml examples/anim/*.toml; do
        # [dynamic] designs have no surface (err_surface_dynamic); a morph file needs --time.
        grep -q -E '^\[(dynamic|morph)\]' "$f" && continue
        b="$(basename "$f" .toml)"
        [ "${f#examples/anim/}" != "$f" ] && b="anim_$b"
        ext="${exts[k % 5]}"
        k=$((k + 1))
        c "surface_all_$b" surface "$f" -o "@/$b.$ext" --nu 12 --nv 24
    done

    # --- check and analyze
    for f in examples/*.toml examples/spline/*.toml examples/anim/*.toml; do
        b="$(basename "$f" .toml)"
        [ "${f#examples/anim/}" != "$f" ] && b="anim_$b"
        c "check_$b" check "$f"
    done
    c check_json check examples/cup.toml --json
    c check_json_spine check examples/spine_bend.toml --json
    c check_set check examples/swirl_port_params.toml --set twist=0.5
    for b in cup cup_closed klein_bottle trimmed_vase vesicle water_glass spine_bend blend_cylinders; do
        c "analyze_$b" analyze "examples/$b.toml"
    done
    c analyze_json analyze examples/wine_glass.toml --json
    c analyze_tolerance analyze examples/aeroplane.toml --tolerance 1e-6
    c analyze_set analyze examples/swirl_port_params.toml --set s=1.2 --json
    c analyze_time analyze examples/anim/ventricle.toml

    # --- render
    local r=(--size 160x120 "${g[@]}")
    c render_wine render examples/wine_glass.toml -o @/w.png "${r[@]}"
    c render_gauss render examples/wine_glass.toml -o @/w.png "${r[@]}" --color gauss
    c render_mean_range render examples/cup.toml -o @/c.png "${r[@]}" --color mean --range -1,1 --view 1,0,0.3
    c render_klein render examples/klein_bottle.toml -o @/k.png "${r[@]}"
    c render_trimmed render examples/trimmed_vase.toml -o @/t.png "${r[@]}" --view 0,-1,0.5
    c render_aeroplane render examples/aeroplane.toml -o @/a.png --size 200x100
    c render_spine render examples/spine_bend.toml -o @/s.png "${r[@]}"

    # --- curve ([dynamic])
    c curve_interpolate curve examples/dynamic_interpolate.toml -o @/c.csv --frames @/frames.csv --picture @/c.svg
    c curve_section33 curve examples/dynamic_section33.toml -o @/c.csv --frames @/frames.csv --picture @/c.svg
    c curve_section33_plain curve examples/dynamic_section33.toml -o @/c.csv

    # --- spline ([spline])
    for f in examples/spline/*.toml; do
        b="$(basename "$f" .toml)"
        c "spline_${b}_json" spline "$f" -o "@/$b.json"
        c "spline_${b}_igs" spline "$f" -o "@/$b.igs"
        c "spline_${b}_obj" spline "$f" -o "@/$b.obj" --nu 8 --nv 10
    done
    c spline_stl spline examples/spline/coons_bspline.toml -o @/c.stl --nu 8 --nv 8
    c spline_glb spline examples/spline/example1.toml -o @/e.glb --nu 8 --nv 8
    c spline_stdout_json spline examples/spline/example1.toml -o - --format json
    c spline_iges_ext spline examples/spline/biharmonic_bezier.toml -o @/b.iges

    # --- blend ([blend])
    c blend_obj blend examples/blend_cylinders.toml -o @/b.obj --nu 8 --nv 16
    c blend_json blend examples/blend_cylinders.toml -o @/b.json
    c blend_glb blend examples/blend_cylinders.toml -o @/b.glb --nu 8 --nv 16 --up y
    c blend_ply_scale blend examples/blend_cylinders.toml -o @/b.ply --nu 8 --nv 16 --scale 2
    c blend_timings blend examples/blend_cylinders.toml -o @/b.csv --nu 4 --nv 6 --timings

    # --- animate (the examples' [time] cut to 4 frames in the template)
    local a=(--nu 12 --nv 24)
    c animate_ventricle animate examples/anim/ventricle.toml -o @/v.glb "${a[@]}" \
        --csv @/v.csv --plot @/v.svg --frames-dir @/frames --apng @/v.png --gif @/v.gif \
        --contact-sheet @/sheet.png --picture-size 96x72
    c animate_morph animate examples/anim/glass_morph.toml -o @/g.glb "${a[@]}" --csv @/g.csv
    c animate_arm animate examples/anim/arm.toml -o @/arm.glb "${a[@]}" --plot @/arm.svg
    c animate_fish animate examples/anim/fish.toml -o @/fish.glb "${a[@]}" --scale 0.5
    c animate_snake animate examples/anim/snake.toml -o @/snake.glb "${a[@]}" --gif @/s.gif \
        --picture-size 64x48 --view 0,0,1
    c animate_face_retarget animate examples/anim/face.toml -o @/face.glb "${a[@]}" \
        --retarget examples/anim/face_scan.obj --retarget-output @/scan.glb

    # --- fit (meshes written by BEFORE_BIN into fixtures/)
    c fit_sections fit fixtures/vesicle.stl -o @/fit.toml --sections 3
    c fit_adaptive fit fixtures/vesicle.stl -o @/fit.toml --tolerance 0.01 --json @/fit.json --picture @/fit.png
    c fit_ply fit fixtures/vesicle.ply -o @/fit.toml --tolerance 0.005
    c fit_obj_tube fit fixtures/fish.obj -o @/fit.toml --sections 3 --json @/fit.json
    c fit_obj_sheet fit fixtures/sheet.obj -o @/fit.toml --picture @/fit.png

    # --- roundtrip (STEP/IGES written by BEFORE_BIN into fixtures/)
    c roundtrip_step roundtrip examples/cup.toml fixtures/cup.step
    c roundtrip_igs roundtrip examples/cup.toml fixtures/cup.igs --tolerance 1e-3

    # --- optimize (tiny searches; both thread counts, as the result must not depend on them)
    local o=(--evaluations 40 --chains 2 --polish 10 --nu 12 --nv 24)
    c optimize_curvature_t1 optimize examples/optimize_curvature.toml -o @/best.toml "${o[@]}" --threads 1
    c optimize_curvature_t2 optimize examples/optimize_curvature.toml -o @/best.toml "${o[@]}" --threads 2
    c optimize_vesicle optimize examples/vesicle.toml -o @/best.toml --evaluations 20 --chains 2 \
        --polish 5 --seed 7 --nu 12 --nv 24 --threads 2

    # --- shell (CalculiX)
    if [ "$have_ccx" = 1 ]; then
        c shell_yoghurt shell examples/yoghurt.toml --elements 4 -o @/y.csv
        c shell_yoghurt_json shell examples/yoghurt.toml --elements 4 --thickness 0.0006 --json -o @/y.vtu
        c render_shear render examples/yoghurt.toml -o @/y.png "${r[@]}" --color shear
    else
        skip shell "no CalculiX: '$ccx_program' not found (set PDESHAPE_CCX or install calculix-ccx)"
    fi

    # --- errors: one line on stderr, the status, and no file written
    c err_no_subcommand
    c err_unknown_subcommand frobnicate
    c err_unknown_flag surface examples/cup.toml -o @/c.obj --frobnicate
    c err_bad_toml check fixtures/bad_syntax.toml
    c err_bad_toml_surface surface fixtures/bad_syntax.toml -o @/c.obj
    c err_missing_file surface fixtures/no_such_design.toml -o @/c.obj
    c err_missing_mesh fit fixtures/no_such_mesh.stl -o @/f.toml
    c err_unknown_curve check fixtures/unknown_curve.toml
    c err_unknown_curve_json check fixtures/unknown_curve.toml --json
    c err_unknown_field surface fixtures/unknown_field.toml -o @/c.obj
    c err_wrong_type render fixtures/wrong_type.toml -o @/c.png
    c err_negative_radius analyze fixtures/negative_radius.toml
    c err_bad_extension surface examples/cup.toml -o @/c.xyz
    c err_png_from_surface surface examples/cup.toml -o @/c.png
    c err_curve_extension curve examples/dynamic_section33.toml -o @/c.json
    c err_optimize_extension optimize examples/optimize_curvature.toml -o @/best.obj
    c err_fit_extension fit examples/cup.toml -o @/f.toml
    c err_roundtrip_extension roundtrip examples/cup.toml examples/cup.toml
    c err_nu_zero surface examples/cup.toml -o @/c.obj --nu 0
    c err_nu_text surface examples/cup.toml -o @/c.obj --nu abc
    c err_grid_too_large surface examples/cup.toml -o @/c.obj --nu 100000 --nv 100000
    c err_memory_budget PDESHAPE_MAX_MEMORY=1000000 surface examples/cup.toml -o @/c.obj --nu 200 --nv 400
    c err_scale surface examples/cup.toml -o @/c.obj --scale=-1
    c err_up surface examples/cup.toml -o @/c.obj --up w
    c err_nu_for_step surface examples/cup.toml -o @/c.step --nu 16
    c err_units surface examples/cup.toml -o @/c.step --units furlong
    c err_size render examples/cup.toml -o @/c.png --size 0x10
    c err_size_format render examples/cup.toml -o @/c.png --size 10
    c err_view render examples/cup.toml -o @/c.png --view 0,0,0
    c err_range render examples/cup.toml -o @/c.png --color gauss --range 1,0
    c err_tolerance analyze examples/cup.toml --tolerance 0
    c err_set_unknown surface examples/swirl_port_params.toml -o @/c.obj --set nosuch=1
    c err_set_bounds surface examples/swirl_port_params.toml -o @/c.obj --set theta=100
    c err_curve_no_dynamic curve examples/cup.toml -o @/c.csv
    c err_spline_no_section spline examples/cup.toml -o @/s.json
    c err_blend_no_section blend examples/cup.toml -o @/b.obj
    c err_optimize_no_section optimize examples/cup.toml -o @/b.toml
    c err_surface_dynamic surface examples/dynamic_interpolate.toml -o @/c.obj
    c err_fit_two_pieces fit examples/anim/face_scan.obj -o @/f.toml
    # An OBJ of several patches (one `o` object each) is read as separate components.
    c err_fit_obj_patches fit fixtures/vesicle.obj -o @/f.toml
    c err_retarget_output animate examples/anim/arm.toml -o @/a.glb --retarget examples/anim/face_scan.obj
    c err_shell_no_ccx PDESHAPE_CCX=/nonexistent/ccx shell examples/yoghurt.toml
    seed err_read_only fixtures/readonly.obj c.obj 444
    c err_read_only surface examples/cup.toml -o @/c.obj --nu 4 --nv 4
    seed force_read_only fixtures/readonly.obj c.obj 444
    c force_read_only --force surface examples/cup.toml -o @/c.obj --nu 4 --nv 4
}

# The template tree: examples/ (animations at 4 frames) and fixtures/.
make_template() {
    local t="$root/template"
    mkdir -p "$t/fixtures"
    cp -a "$repo/examples" "$t/examples"
    local f
    for f in "$t"/examples/anim/*.toml; do
        sed -i -E 's/^frames = [0-9]+/frames = 4/' "$f"
    done
    local fx="$t/fixtures"
    printf 'title = "unterminated\n[operator]\nkind = "polyharmonic"\n' >"$fx/bad_syntax.toml"
    sed 's/curve = "rim" }/curve = "nosuch" }/' "$repo/examples/cup.toml" >"$fx/unknown_curve.toml"
    sed 's/^scale = 1.2$/scael = 1.2/' "$repo/examples/cup.toml" >"$fx/unknown_field.toml"
    sed 's/^order = 2$/order = "two"/' "$repo/examples/cup.toml" >"$fx/wrong_type.toml"
    sed 's/^radius = 1.35$/radius = -1.35/' "$repo/examples/cup.toml" >"$fx/negative_radius.toml"
    local d
    for d in unknown_curve unknown_field wrong_type negative_radius; do
        if cmp -s "$fx/$d.toml" "$repo/examples/cup.toml"; then
            echo "$0: fixtures/$d.toml: the edit of examples/cup.toml did not apply" >&2
            exit 2
        fi
    done
    printf 'not a mesh\n' >"$fx/readonly.obj"
    # Inputs of fit and roundtrip, written by BEFORE_BIN (the same bytes for both runs).
    local fixture_cmds=(
        "surface examples/vesicle.toml -o fixtures/vesicle.stl --nu 16 --nv 32"
        "surface examples/vesicle.toml -o fixtures/vesicle.ply --nu 12 --nv 24"
        "surface examples/vesicle.toml -o fixtures/vesicle.obj --nu 12 --nv 20"
        "surface examples/anim/fish.toml -o fixtures/fish.obj --nu 12 --nv 24"
        "surface examples/spline/biharmonic_bezier.toml -o fixtures/sheet.obj --nu 12 --nv 24"
        "surface examples/cup.toml -o fixtures/cup.step"
        "surface examples/cup.toml -o fixtures/cup.igs"
    )
    mkdir -p "$root/bin-fixtures"
    ln -s "$before_bin" "$root/bin-fixtures/pdeshape"
    local cmd
    for cmd in "${fixture_cmds[@]}"; do
        # shellcheck disable=SC2086 # the words of the command
        if ! (cd "$t" && env -i "${base_env[@]}" PATH="$root/bin-fixtures:$PATH" \
            pdeshape -q $cmd </dev/null >/dev/null 2>"$root/fixture.err"); then
            echo "$0: making a fixture with BEFORE_BIN failed: pdeshape $cmd: $(cat "$root/fixture.err")" >&2
            exit 2
        fi
    done
}

# run_all LABEL BIN: the cases with BIN in a fresh copy of the template, left in $root/LABEL.
run_all() {
    local label="$1" bin="$2"
    bindir="$root/bin-$label"
    mkdir -p "$bindir"
    ln -s "$bin" "$bindir/pdeshape"
    rm -rf "$root/run"
    cp -a "$root/template" "$root/run"
    mkdir "$root/run/out" "$root/run/res"
    names=()
    : >"$root/skipped-$label"
    local start=$SECONDS
    (cd "$root/run" && cases && printf '%s\n' "${names[@]}" >"$root/names-$label")
    echo "# $label: $(wc -l <"$root/names-$label") cases in $((SECONDS - start)) s ($bin)"
    mv "$root/run" "$root/$label"
}

# normalise TREE: the substitutions N1-N7 described at the top, in place.
normalise() {
    local t="$1" f
    # N1 --timings
    sed -i -E 's/"([a-z_]+_ms)":[-0-9.eE+]+/"\1":<ms>/g' "$t"/res/*.stderr
    # N2 curve wall time
    sed -i -E -e 's/^(steps: .* in) [-0-9.eE+]+ s$/\1 <s> s/' \
        -e 's/^(interpolating curve: .* force updates), [-0-9.eE+]+ s$/\1, <s> s/' \
        "$t"/res/curve_*.stdout
    # N3 fit time
    sed -i -E 's/\) in [0-9]+ ms; Hausdorff/) in <ms> ms; Hausdorff/' "$t"/res/fit_*.stdout
    # N4 fit --json timings
    for f in "$t"/out/fit_*/*.json; do
        [ -f "$f" ] || continue
        sed -i -E '/"timings_ms": \{/,/\}/ s/^( *"[a-z_]+": )[-0-9.eE+]+(,?)$/\1"<ms>"\2/' "$f"
    done
    # N5, N6 CAD time stamps of `surface`
    for f in "$t"/out/surface_*/*.step "$t"/out/surface_*/*.stp; do
        [ -f "$f" ] || continue
        sed -i -E "s/^(FILE_NAME\('[^']*',)'[0-9]{4}-[0-9]{2}-[0-9]{2}T[0-9]{2}:[0-9]{2}:[0-9]{2}'/\1'<time>'/" "$f"
    done
    for f in "$t"/out/surface_*/*.igs "$t"/out/surface_*/*.iges; do
        [ -f "$f" ] || continue
        sed -i -E '/G +[0-9]+$/ s/15H[0-9]{8}\.[0-9]{6}/15HYYYYMMDD.HHMMSS/g' "$f"
    done
    # N7 shell times
    if [ "$have_ccx" = 1 ]; then
        sed -i -E 's/^time: meshing .*/time: <s>/' "$t"/res/shell_*.stdout
        sed -i -E '/"seconds": \{/,/\}/ s/^( *"[a-z_]+": )[-0-9.eE+]+(,?)$/\1"<s>"\2/' "$t"/res/shell_*.stdout
    fi
}

# What differs in case NAME between the trees (empty if nothing).
differences() {
    local name="$1" A="$root/before" B="$root/after" what=() s
    if ! cmp -s "$A/res/$name.status" "$B/res/$name.status"; then
        what+=("exit status $(cat "$A/res/$name.status") vs $(cat "$B/res/$name.status")")
    fi
    for s in stdout stderr; do
        cmp -s "$A/res/$name.$s" "$B/res/$name.$s" || what+=("$s")
    done
    local listing_a listing_b
    listing_a="$(cd "$A/out/$name" && find . -mindepth 1 -printf '%M %p\n' | sort)"
    listing_b="$(cd "$B/out/$name" && find . -mindepth 1 -printf '%M %p\n' | sort)"
    if [ "$listing_a" != "$listing_b" ]; then
        local only_a only_b
        only_a="$(comm -23 <(echo "$listing_a") <(echo "$listing_b") | sed 's#\./##' | paste -sd' ')"
        only_b="$(comm -13 <(echo "$listing_a") <(echo "$listing_b") | sed 's#\./##' | paste -sd' ')"
        what+=("files written: before only [${only_a}], after only [${only_b}]")
    fi
    local p
    while IFS= read -r p; do
        [ -f "$B/out/$name/$p" ] || continue
        cmp -s "$A/out/$name/$p" "$B/out/$name/$p" || what+=("${p#./}")
    done < <(cd "$A/out/$name" && find . -type f | sort)
    local sep="" w
    for w in "${what[@]}"; do
        printf '%s%s' "$sep" "$w"
        sep="; "
    done
}

make_template
run_all before "$before_bin"
run_all after "$after_bin"
if ! cmp -s "$root/names-before" "$root/names-after"; then
    echo "$0: the two runs ran different case lists" >&2
    exit 2
fi
if [ "$(sort "$root/names-before" | uniq -d)" != "" ]; then
    echo "$0: duplicate case names: $(sort "$root/names-before" | uniq -d | tr '\n' ' ')" >&2
    exit 2
fi
normalise "$root/before"
normalise "$root/after"

passed=0
failed=0
while IFS= read -r name; do
    d="$(differences "$name")"
    if [ -z "$d" ]; then
        echo "$name: same"
        passed=$((passed + 1))
    else
        echo "$name: DIFFERS: $d"
        failed=$((failed + 1))
    fi
done <"$root/names-before"

# Anything written outside out/CASE/ (beside the examples or fixtures, or a stray out/ entry).
rest="$(diff -rq --no-dereference -x res "$root/before" "$root/after" 2>&1 |
    grep -v -E "^(Files|Only in) $root/(before|after)/out/($(paste -sd'|' "$root/names-before"))[/: ]" |
    sed "s#$root/##g")"
if [ -z "$rest" ]; then
    echo "files outside out/CASE: same"
    passed=$((passed + 1))
else
    echo "files outside out/CASE: DIFFERS: $(echo "$rest" | tr '\n' ';' | sed 's/;$//')"
    failed=$((failed + 1))
fi

cat "$root/skipped-before"
echo "$passed passed, $failed failed"
[ "$failed" -eq 0 ]
