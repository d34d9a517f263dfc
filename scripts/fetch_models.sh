#!/usr/bin/env bash
# Downloads the detector models of `dynorb run --mode semantic` from their upstream repositories
# at pinned commits and verifies their sha256 (the sums of each model's SOURCE.txt). The project
# never commits weights. Usage:
#   scripts/fetch_models.sh [--dest DIR] [MODEL...]     (default DIR: models/, default: all)
# then: dynorb run --mode semantic --models DIR ...
set -euo pipefail

dest="models"
models=()
while [[ $# -gt 0 ]]; do
  case "$1" in
    --dest)
      [[ $# -ge 2 && -n "$2" ]] || { echo "--dest needs a folder (e.g. --dest models)" >&2; exit 2; }
      dest="$2"; shift 2 ;;
    -h|--help) sed -n '2,6p' "$0"; exit 0 ;;
    *) models+=("$1"); shift ;;
  esac
done
all=(yolo_fastest_1.1 yolo_fastest_1.1_xl yolo_fastest_1.1_body yolox_nano fastestdet nanodet_m_320)
[[ ${#models[@]} -eq 0 ]] && models=("${all[@]}")

YF="https://raw.githubusercontent.com/dog-qiuqiu/Yolo-Fastest/96a2900d163196c396e73f3fdab04ca4dd9a2f70"
FD="https://raw.githubusercontent.com/dog-qiuqiu/FastestDet/50473cd155cb088aa4a99e64ff6a4b3c24fa07e1"
ND="https://raw.githubusercontent.com/hpc203/nanodet-opncv-dnn-cpp-python/15dd99c651d53c824f51d1eb5faddbd4f3d69bbc"
YX="https://raw.githubusercontent.com/Bigisland1729/object-detection-models/7f3f2fa34b351e3d2af150893458106ad3f3a84f"
COCO_SHA=634a1132eb33f8091d60f2c346ababe8b905ae08387037aed883953b7329af84

# Lines: model file url sha256
manifest() {
  cat <<LIST
yolo_fastest_1.1 yolo-fastest-1.1.cfg $YF/ModelZoo/yolo-fastest-1.1_coco/yolo-fastest-1.1.cfg f6df5775c1e862998cf69046eba9265be3ae84dfe8b2caab7529823f0795bf70
yolo_fastest_1.1 yolo-fastest-1.1.weights $YF/ModelZoo/yolo-fastest-1.1_coco/yolo-fastest-1.1.weights 1c445c42bbd6df63edea2cc69f99667b5650d663ca11e34b116240740cd42890
yolo_fastest_1.1 coco.names $ND/coco.names $COCO_SHA
yolo_fastest_1.1 LICENSE $YF/LICENSE 2021f0b8d6426fbf9a2f0126f1e8a7d3b1d7027c871b9979fa2543b9557000c4
yolo_fastest_1.1_xl yolo-fastest-1.1-xl.cfg $YF/ModelZoo/yolo-fastest-1.1_coco/yolo-fastest-1.1-xl.cfg c458427acc4fbeabceff4528ef7b65b066c0308ce599460f8ba299eba63abad3
yolo_fastest_1.1_xl yolo-fastest-1.1-xl.weights $YF/ModelZoo/yolo-fastest-1.1_coco/yolo-fastest-1.1-xl.weights fac5fb41786c1f38f04972a658443b189f48720d7d117f9a044100e98a35b0c5
yolo_fastest_1.1_xl coco.names $ND/coco.names $COCO_SHA
yolo_fastest_1.1_xl LICENSE $YF/LICENSE 2021f0b8d6426fbf9a2f0126f1e8a7d3b1d7027c871b9979fa2543b9557000c4
yolo_fastest_1.1_body yolo-fastest-1.1_body.cfg $YF/ModelZoo/yolo-fastest-1.1_body/yolo-fastest-1.1_body.cfg 045b8e276ebe3924474da8c866b7e709159ea067137b5d66bf9dd560411b2c1a
yolo_fastest_1.1_body yolo-fastest-1.1_body.weights $YF/ModelZoo/yolo-fastest-1.1_body/yolo-fastest-1.1_body.weights 5bbb6d878f6e2eb3deee39e91dc6f9b39700e99ec83fa94d258670a554949728
yolo_fastest_1.1_body body.names - 9e2ec912af5dff2a72300863864fc4da04e81999339d9fac5c7590ba8a3f4e11
yolo_fastest_1.1_body LICENSE $YF/LICENSE 2021f0b8d6426fbf9a2f0126f1e8a7d3b1d7027c871b9979fa2543b9557000c4
yolox_nano yolox_nano.onnx $YX/yolox_nano.onnx e8af074932d4ed7e232278e3055cefcdea3edf178874a3694ae292649fb464dd
yolox_nano coco.names $ND/coco.names $COCO_SHA
fastestdet FastestDet.onnx $FD/example/onnx-runtime/FastestDet.onnx 31cb14c017fce347cb4c846ec62fdf00d76bb3beecdf4be21e7116ac67feb880
fastestdet coco.names $FD/example/onnx-runtime/coco.names $COCO_SHA
fastestdet LICENSE.md $FD/LICENSE 1269ab6dbd957fa0499672227cf9c98ed9bfadeafcf85d391fc066d7551609ad
nanodet_m_320 nanodet.onnx $ND/nanodet.onnx c59b6c947ce475d27023327808aed655fa000981fe144c4fd2026828999e19f8
nanodet_m_320 coco.names $ND/coco.names $COCO_SHA
LIST
}

# Refuse unknown names (exact, whole-name comparison) and missing tools before creating anything.
for model in "${models[@]}"; do
  known=0
  for m in "${all[@]}"; do [[ "$model" == "$m" ]] && known=1; done
  if [[ $known -eq 0 ]]; then
    echo "unknown model ${model@Q} (known: ${all[*]})" >&2; exit 2
  fi
done
missing=()
for tool in curl sha256sum; do command -v "$tool" >/dev/null || missing+=("$tool"); done
if [[ ${#missing[@]} -gt 0 ]]; then
  echo "fetch_models.sh needs ${missing[*]}, not found on PATH (Debian: apt-get install curl coreutils, or make deps)" >&2
  exit 2
fi

# The file being downloaded; removed if the script is interrupted before it is checked.
part=""
trap '[[ -z "$part" ]] || rm -f -- "$part"' EXIT
failed=0
for model in "${models[@]}"; do
  mkdir -p "$dest/$model"
  while read -r name file url sha; do
    [[ "$name" == "$model" ]] || continue
    out="$dest/$model/$file"
    if [[ -f "$out" ]]; then
      if echo "$sha  $out" | sha256sum -c --status; then
        echo "ok       $out"; continue
      fi
      # Never leave a file with a wrong sum at its final name (dynorb does not check sums at load).
      rm -f -- "$out"; echo "removed  $out (sha256 mismatch; fetching it again)"
    fi
    part="$out.part"
    if [[ "$url" == "-" ]]; then
      printf 'body\n' > "$part"   # the body model's one-line class list (not a file upstream)
    else
      echo "fetch    $url"
      if ! err=$(curl -fsSL --retry 3 -o "$part" "$url" 2>&1); then
        rm -f -- "$part"; part=""
        err=${err##*$'\n'}
        echo "FAILED download $url${err:+ ($err)}" >&2; failed=$((failed + 1)); continue
      fi
    fi
    if echo "$sha  $part" | sha256sum -c --status; then
      mv -f -- "$part" "$out"; part=""; echo "verified $out"
    else
      rm -f -- "$part"; part=""
      echo "SHA256 MISMATCH for $out (expected $sha); download removed" >&2; failed=$((failed + 1))
    fi
  done < <(manifest)
done
[[ $failed -eq 0 ]] || { echo "$failed file(s) failed; see above" >&2; exit 1; }
echo "models in $dest; use: dynorb run --mode semantic --models $dest ..."
