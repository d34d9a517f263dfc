#!/usr/bin/env bash
# `dynorb vocab` (CTest: dynorb_cli_vocab): trains a vocabulary from images that `dynorb run`
# then uses (place_recognition: {vocabulary: FILE}); bad input is one message, exit 2, no file.
# Usage: vocab_test.sh path/to/dynorb
set -uo pipefail
source "$(dirname "${BASH_SOURCE[0]}")/test_lib.sh"

"$DYNORB" synth --preset walking_xyz --frames 30 --people procedural --out "$DIR/seq" >/dev/null 2>&1 ||
  { echo "FAIL: synth"; exit 1; }
SEQ="$DIR/seq"

out=$("$DYNORB" vocab --images "$SEQ/rgb" --branching 6 --levels 3 --out "$DIR/v.dynvoc" 2>&1) || fail "vocab: exit code $?"
grep -q "^wrote $DIR/v.dynvoc: [0-9]* words (branching 6, 3 levels) from [0-9]* descriptors of 30 images" <<<"$out" ||
  fail "vocab: unexpected summary: $out"
[[ -s "$DIR/v.dynvoc" ]] || fail "vocab: no file"
"$DYNORB" vocab --images "$SEQ/rgb" --branching 6 --levels 3 --out "$DIR/again.dynvoc" >/dev/null 2>&1
cmp -s "$DIR/v.dynvoc" "$DIR/again.dynvoc" || fail "vocab: training twice gave different files"

# A run with it, and the effective config says which.
cp "$SEQ/camera.yaml" "$DIR/with_vocab.yaml"
printf 'place_recognition:\n  vocabulary: %s\n' "$DIR/v.dynvoc" >>"$DIR/with_vocab.yaml"
"$DYNORB" run --dataset "$SEQ" --config "$DIR/with_vocab.yaml" --out "$DIR/run" --quiet >/dev/null 2>&1 ||
  fail "run with the vocabulary: exit code $?"
grep -q "vocabulary: .*v.dynvoc" "$DIR/run/effective_config.yaml" || fail "effective_config.yaml does not name the vocabulary"

# The loop_closing: section: switched off, and its values checked.
cp "$SEQ/camera.yaml" "$DIR/no_loops.yaml"
printf 'loop_closing:\n  enabled: false\n  min_agreement: 0.2\n  global_ba: false\n  global_ba_iterations: 7\n  global_ba_thread: true\n' >>"$DIR/no_loops.yaml"
"$DYNORB" run --dataset "$SEQ" --config "$DIR/no_loops.yaml" --out "$DIR/no_loops" --quiet >/dev/null 2>&1 ||
  fail "run with loop_closing: {enabled: false}: exit code $?"
grep -q "min_agreement: 0.2" "$DIR/no_loops/effective_config.yaml" || fail "effective_config.yaml lacks loop_closing.min_agreement"
grep -q '"loops_closed": 0' "$DIR/no_loops/stats.json" || fail "stats.json lacks loops_closed"
grep -q "global_ba: false" "$DIR/no_loops/effective_config.yaml" || fail "effective_config.yaml lacks loop_closing.global_ba"
grep -q "global_ba_iterations: 7" "$DIR/no_loops/effective_config.yaml" || fail "effective_config.yaml lacks loop_closing.global_ba_iterations"
grep -q "global_ba_thread: true" "$DIR/no_loops/effective_config.yaml" || fail "effective_config.yaml lacks loop_closing.global_ba_thread"
grep -q '"global_bundle_adjustments": \[\]' "$DIR/no_loops/stats.json" || fail "stats.json lacks global_bundle_adjustments"

# Bad input: one message naming the problem, exit code 2, nothing written.
expect_error() {  # expect_error WHAT PATTERN OUTPUT_PATH command...
  local what=$1 pattern=$2 written=$3
  shift 3
  local msg code
  msg=$("$@" 2>&1)
  code=$?
  [[ $code == 2 ]] || fail "$what: exit code $code, expected 2 ($msg)"
  grep -q -- "$pattern" <<<"$msg" || fail "$what: message '$msg' lacks '$pattern'"
  [[ -e $written ]] && fail "$what: $written was written"
}
mkdir -p "$DIR/empty"
expect_error "no images" "$DIR/empty: no image files" "$DIR/x1.dynvoc" \
  "$DYNORB" vocab --images "$DIR/empty" --out "$DIR/x1.dynvoc"
expect_error "missing input" "$DIR/nope: no such file or directory" "$DIR/x2.dynvoc" \
  "$DYNORB" vocab --images "$DIR/nope" --out "$DIR/x2.dynvoc"
echo "not an image" >"$DIR/fake.png"
expect_error "unreadable image" "$DIR/fake.png: cannot read this image" "$DIR/x3.dynvoc" \
  "$DYNORB" vocab --images "$DIR/fake.png" --out "$DIR/x3.dynvoc"
expect_error "branching 1" "branching must be in 2..64" "$DIR/x4.dynvoc" \
  "$DYNORB" vocab --images "$SEQ/rgb" --branching 1 --out "$DIR/x4.dynvoc"
head -c 1000 "$DIR/v.dynvoc" >"$DIR/truncated.dynvoc"
cp "$SEQ/camera.yaml" "$DIR/bad_vocab.yaml"
printf 'place_recognition:\n  vocabulary: %s\n' "$DIR/truncated.dynvoc" >>"$DIR/bad_vocab.yaml"
expect_error "truncated vocabulary" "$DIR/truncated.dynvoc: vocabulary file is corrupt" "$DIR/bad_run/stats.json" \
  "$DYNORB" run --dataset "$SEQ" --config "$DIR/bad_vocab.yaml" --out "$DIR/bad_run" --quiet

cp "$SEQ/camera.yaml" "$DIR/bad_agreement.yaml"
printf 'loop_closing:\n  min_agreement: 2\n' >>"$DIR/bad_agreement.yaml"
expect_error "min_agreement 2" "min_agreement must be in \[0, 1\]" "$DIR/bad_agreement_run/stats.json" \
  "$DYNORB" run --dataset "$SEQ" --config "$DIR/bad_agreement.yaml" --out "$DIR/bad_agreement_run" --quiet
cp "$SEQ/camera.yaml" "$DIR/bad_gba.yaml"
printf 'loop_closing:\n  global_ba_iterations: 0\n' >>"$DIR/bad_gba.yaml"
expect_error "global_ba_iterations 0" "global_ba_iterations >= 1" "$DIR/bad_gba_run/stats.json" \
  "$DYNORB" run --dataset "$SEQ" --config "$DIR/bad_gba.yaml" --out "$DIR/bad_gba_run" --quiet
expect_error "output folder missing" "output directory does not exist" "$DIR/nodir/v.dynvoc" \
  "$DYNORB" vocab --images "$SEQ/rgb" --out "$DIR/nodir/v.dynvoc"

finish "vocab checks"
