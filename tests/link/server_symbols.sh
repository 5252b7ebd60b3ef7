#!/usr/bin/env bash
# nidevo-server carries none of the offline tools' code: no dataset reader, no evaluation or
# plots, no sequence flags. (OpenCV imgcodecs it does link: JPEG/PNG frames are decoded with it.)
# Usage: server_symbols.sh <nidevo-server binary>
set -euo pipefail
binary="$1"
symbols=$(nm -C "$binary")
status=0
for forbidden in 'nidevo::TumDataset' 'nidevo::readFileList' 'nidevo::writeTrajectoryPlot' \
  'nidevo::computeAte' 'nidevo::cli::loadSequence' 'nidevo::synth::' 'FLAGS_dataset'; do
  if grep -qF "$forbidden" <<<"$symbols"; then
    echo "nidevo-server links code it never uses: $forbidden" >&2
    status=1
  fi
done
[ $status -eq 0 ] && echo "nidevo-server: no dataset reader, evaluation, plot, renderer or sequence-flag code"
exit $status
