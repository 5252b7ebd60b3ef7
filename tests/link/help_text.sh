#!/usr/bin/env bash
# Every executable answers --help with exit 0, its usage and its flags under readable headings,
# and never the build machine's source paths. Usage: help_text.sh <bin dir> <source dir>
set -euo pipefail
bin="$1"
src="$2"
status=0
for tool in nidevo-run nidevo-synth nidevo-eval nidevo-server nidevo-client; do
  [ -x "$bin/$tool" ] || continue
  if ! out=$("$bin/$tool" --help 2>&1); then
    echo "$tool --help: exit status not 0" >&2
    status=1
    continue
  fi
  if grep -qE 'Flags from|\.cpp|'"$src" <<<"$out"; then
    echo "$tool --help names source files:" >&2
    grep -E 'Flags from|\.cpp|'"$src" <<<"$out" | head -3 >&2
    status=1
  fi
  if ! grep -qE '^Options:$|^Server:$|^Connection' <<<"$out" || ! grep -qE '^  --[a-z_]+=' <<<"$out"; then
    echo "$tool --help: no heading or no flag listed" >&2
    status=1
  fi
  echo "$tool --help: $(grep -cE '^  --' <<<"$out") flags under $(grep -cE '^[A-Za-z].*:$' <<<"$out") headings"
done
exit $status
