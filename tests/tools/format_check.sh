#!/usr/bin/env bash
# Every C++ source and header is as clang-format leaves it (.clang-format:
# Google style, 100 columns). Fails naming the files to format and the
# command that formats them; skipped (77) where clang-format is absent, as
# on a machine set up without workflows/test.sh.
# usage: format_check.sh SOURCE_DIR
set -euo pipefail
cd "$1"
if ! command -v clang-format > /dev/null; then
  echo "skipped: clang-format is not installed (workflows/test.sh installs it)"
  exit 77
fi
if [ -d .git ] && command -v git > /dev/null; then
  mapfile -t files < <(git ls-files '*.cc' '*.h')
else
  mapfile -t files < <(find . -path ./build -prune -o \( -name '*.cc' -o -name '*.h' \) -print | sort)
fi
# One process for all files; each file not formatted is named in an
# "error: code should be clang-formatted" line.
mapfile -t unformatted < <(clang-format --dry-run --Werror "${files[@]}" 2>&1 |
  sed -n 's/^\([^:]*\):[0-9]*:[0-9]*: error: code should be clang-formatted.*/\1/p' | sort -u)
echo "$(clang-format --version | head -1): ${#files[@]} files, ${#unformatted[@]} not formatted"
if [ "${#unformatted[@]}" -gt 0 ]; then
  printf '  %s\n' "${unformatted[@]}"
  echo "format them with: clang-format -i ${unformatted[*]}"
  exit 1
fi
