#!/usr/bin/env bash
# Every tracked C++ and proto file is as clang-format (the repository's .clang-format) writes it.
# Usage: check_format.sh <source dir>
set -euo pipefail
cd "$1"
mapfile -t files < <(git ls-files '*.cpp' '*.hpp' '*.h' '*.proto' 2>/dev/null || true)
if [ ${#files[@]} -eq 0 ]; then
  mapfile -t files < <(find core server client tests proto -name '*.cpp' -o -name '*.hpp' -o -name '*.proto')
fi
clang-format --dry-run --Werror "${files[@]}"
echo "format: ${#files[@]} files as clang-format writes them"
