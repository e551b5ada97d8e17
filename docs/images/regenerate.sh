#!/usr/bin/env bash
# Regenerates the pictures in docs/images/ by the commands listed in
# docs/images/README.md (keep the two in step). Run from anywhere:
#
#   docs/images/regenerate.sh            # every picture it can make
#   docs/images/regenerate.sh spot.png   # only the pictures named
#
# Builds target/release/subdyn, data-gen and the examples first. Pictures
# that need the shared data sets (../shared/data beside the repository, or
# $SUBDYN_SHARED_DATA) are skipped with a message when they are absent.
# fit_spot.png needs benches/compare/run_compare.py, which installs Open3D
# and pymeshlab into a virtualenv: it runs only with REGENERATE_COMPARE=1.
# Temporary files go to a mktemp directory, removed at the end.
set -euo pipefail

root=$(cd "$(dirname "${BASH_SOURCE[0]}")/../.." && pwd)
cd "$root"
target=${CARGO_TARGET_DIR:-$root/target}
shared=${SUBDYN_SHARED_DATA:-$(dirname "$root")/shared/data}
images=docs/images
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT

cargo build --release --workspace --bins --examples --quiet
subdyn() { "$target/release/subdyn" "$@"; }
data_gen() { "$target/release/data-gen" "$@"; }
# Examples write into target/examples-out/ of the repository (examples/common).
examples_out=$root/target/examples-out

made=() skipped=()
# wanted NAME: true when NAME is to be made (all, or named on the command line).
wanted() {
    local name=$1
    [[ ${#selection[@]} -eq 0 ]] && return 0
    local s
    for s in "${selection[@]}"; do [[ $s == "$name" ]] && return 0; done
    return 1
}
# needs_shared NAME: true when the shared data sets are there, else a message.
needs_shared() {
    if [[ -d $shared ]]; then return 0; fi
    echo "skipped $1: needs the shared data sets in $shared (set SUBDYN_SHARED_DATA)"
    skipped+=("$1")
    return 1
}
done_picture() {
    echo "== $images/$1 regenerated"
    made+=("$1")
}
# example_picture NAME EXAMPLE FILE: when NAME is wanted, runs the example
# and copies the FILE it wrote into target/examples-out/ to NAME.
example_picture() {
    wanted "$1" || return 0
    "$target/release/examples/$2"
    cp "$examples_out/$3" "$images/$1"
    done_picture "$1"
}
# middle_axial DIR: the middle one of the axial slice pictures that
# `subdyn recover --slices-png DIR` wrote (their z follows the result).
middle_axial() {
    local files f n
    mapfile -t files < <(for f in "$1"/axial_z*.png; do
        n=${f##*/axial_z}
        echo "${n%.png} $f"
    done | sort -g | cut -d' ' -f2-)
    if [[ ! -e ${files[0]:-} ]]; then
        echo "regenerate.sh: no axial slice picture in $1" >&2
        return 1
    fi
    echo "${files[$((${#files[@]} / 2))]}"
}
selection=("$@")

if wanted spot.png && needs_shared spot.png; then
    subdyn render "$shared/meshes/spot.obj" -o $images/spot.png --view 145,20 --ssaa --quiet
    done_picture spot.png
fi

if wanted fandisk.png && needs_shared fandisk.png; then
    subdyn render "$shared/meshes/fandisk.obj" -o $images/fandisk.png --view 125,30 --ssaa --quiet
    done_picture fandisk.png
fi

if wanted rocker-arm.png && needs_shared rocker-arm.png; then
    subdyn render "$shared/meshes/rocker-arm.obj" -o $images/rocker-arm.png --ssaa --quiet
    done_picture rocker-arm.png
fi

if wanted bunny-scan.png && needs_shared bunny-scan.png; then
    subdyn render "$shared/scans/bun045.ply" -o $images/bunny-scan.png --ssaa \
        --title "bun045.ply: 40,097 points" --quiet
    done_picture bunny-scan.png
fi

if wanted cube-limit-cage.png; then
    subdyn render tests/data/opensubdiv/cube.obj --limit 16 --cage -o $images/cube-limit-cage.png \
        --view 35,25 --ssaa --title "cube: limit surface and control cage" --quiet
    done_picture cube-limit-cage.png
fi

if wanted spot-distance.png && needs_shared spot-distance.png; then
    subdyn limit "$shared/meshes/spot.obj" -o "$tmp/spot-limit.ply" --tess 4 --quiet
    subdyn render "$shared/meshes/spot.obj" --color-by-distance-to "$tmp/spot-limit.ply" \
        -o $images/spot-distance.png --view 145,20 --ssaa \
        --title "spot.obj: distance to its limit surface" --quiet
    done_picture spot-distance.png
fi

if wanted lattice-numbered.png; then
    subdyn lattice tests/data/opensubdiv/cube.obj --octree-levels 1 -o "$tmp/cube_lat.json"
    subdyn render "$tmp/cube_lat.json" --label-vertices -o $images/lattice-numbered.png \
        --view 35,25 --ssaa --title "cube lattice: control points numbered" --quiet
    done_picture lattice-numbered.png
fi

# Reads ../shared/data/meshes/spot.obj, or the same Spot built into the library.
example_picture ffd_spot_bump.png 23_spot_bump spot_bump.png

example_picture finetune_closed_curve.png 30_finetune_closed_curve finetune_closed_curve.png

if wanted fit_plate_creases.png; then
    data_gen scan plate -o "$tmp/plate.ply" --noise 0.001 --views 8 --resolution 128,96 --seed 1
    subdyn fit "$tmp/plate.ply" -o "$tmp/plate_fit.obj" --quiet
    subdyn render "$tmp/plate_fit.obj" --limit 4 --cage -o $images/fit_plate_creases.png \
        --view 35,35 --size 800,600 --ssaa \
        --title "plate scan: fitted cage, creases found in the scan in red" --quiet
    done_picture fit_plate_creases.png
fi

if wanted fit_bun045.png && needs_shared fit_bun045.png; then
    subdyn fit "$shared/scans/bun045.ply" --init auto -o "$tmp/bun_fit.obj" \
        --report "$tmp/bun_rep.json" --plot "$tmp/bun_plot.png" --quiet
    subdyn render "$tmp/bun_fit.obj" --limit 4 --points "$shared/scans/bun045.ply" \
        -o $images/fit_bun045.png --view 0,0 --point-size 0.6 --ssaa \
        --title "bun045: subdyn fit --init auto + scan points" --quiet
    done_picture fit_bun045.png
fi

if wanted fit_spot.png && needs_shared fit_spot.png; then
    if [[ ${REGENERATE_COMPARE:-0} == 1 ]]; then
        python3 benches/compare/run_compare.py --only spot
        subdyn render target/compare/spot/subdyn_limit.ply \
            --color-by-distance-to target/compare/spot.truth.obj \
            -o $images/fit_spot.png --view 15,15 --size 800,600 --quiet
        done_picture fit_spot.png
    else
        echo "skipped fit_spot.png: set REGENERATE_COMPARE=1 (runs benches/compare/run_compare.py, which installs Open3D and pymeshlab)"
        skipped+=(fit_spot.png)
    fi
fi

if wanted demo_fit_distance.png; then
    subdyn fit -o "$tmp/demo_fit.obj" --limit-out "$tmp/demo_surface.ply" --quiet
    subdyn render "$tmp/demo_surface.ply" --color-by-distance-to data/demo/spot_scan.truth.obj.gz \
        -o $images/demo_fit_distance.png --view 145,20 --range 0,0.3 --ssaa \
        --title "demo fit vs truth (% of diagonal)" --quiet
    done_picture demo_fit_distance.png
fi

example_picture drag_surface.png 04_drag_surface drag_surface.png

if wanted fit_genus2_outlier_spike.png; then
    data_gen scan genus2 -o "$tmp/g2.ply" --views 8 --noise 0.001 --outliers 0.05 --seed 1
    subdyn fit "$tmp/g2.ply" -o "$tmp/g2_fit.obj" --limit-out "$tmp/g2_lim.ply" --quiet
    subdyn render "$tmp/g2_lim.ply" --color-by-distance-to "$tmp/g2.truth.obj" \
        -o $images/fit_genus2_outlier_spike.png --view 30,40 --range 0,2 \
        --title "genus2 + 5% outliers: distance to truth, % diag" --quiet
    done_picture fit_genus2_outlier_spike.png
fi

if wanted recover_genus2_slice.png; then
    mkdir -p "$tmp/g2"
    data_gen volume genus2 -o "$tmp/g2/genus2.raw" --format raw --dims 144,84,24 \
        --spacing 0.045,0.045,0.06 --blur 0.03 --noise 0.05
    subdyn recover "$tmp/g2/genus2.json" --iso 0.5 -o "$tmp/g2/fit.obj" \
        --slices-png "$tmp/g2/sl" --quiet
    cp "$(middle_axial "$tmp/g2/sl")" $images/recover_genus2_slice.png
    done_picture recover_genus2_slice.png
fi

if wanted recover_mni_ventricle.png && needs_shared recover_mni_ventricle.png; then
    subdyn recover "$shared/volumes/mni_icbm152_t1_tal_nlin_sym_09a_converted.nii.gz" \
        --auto --seed -6,0,18 --dark --iso 120 -o "$tmp/ventricle.obj" \
        --slices-png "$tmp/vs" --quiet
    cp "$(middle_axial "$tmp/vs")" $images/recover_mni_ventricle.png
    done_picture recover_mni_ventricle.png
fi

if wanted sculpt_demo.png; then
    subdyn sculpt --demo --out-dir "$tmp/sculpt" --quiet
    cp "$tmp/sculpt/sculpt_demo.png" $images/sculpt_demo.png
    done_picture sculpt_demo.png
fi

for s in "${selection[@]}"; do
    case " ${made[*]} ${skipped[*]} " in
        *" $s "*) ;;
        *) echo "regenerate.sh: no picture named $s (see docs/images/README.md)" >&2; exit 1 ;;
    esac
done
echo "${#made[@]} pictures written, ${#skipped[@]} skipped"
