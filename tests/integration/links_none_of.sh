#!/usr/bin/env bash
# links_none_of.sh [--direct] PATTERN BINARY...: fails when any BINARY links a shared library whose
# name matches the extended regular expression PATTERN (case-insensitive). By default every
# library the loader brings in counts (ldd); with --direct only those the binary itself names
# (its NEEDED entries), for libraries that reach it only through a system library's own
# dependencies (OpenCV's image codecs load GDAL, which loads SQLite).
set -u
direct=0
if [ "${1:-}" = "--direct" ]; then
  direct=1
  shift
fi
pattern=$1
shift
status=0
for bin in "$@"; do
  if [ $direct -eq 1 ]; then
    libs=$(readelf -d "$bin" | sed -n 's/.*(NEEDED).*\[\(.*\)\]/\1/p')
  else
    libs=$(ldd "$bin")
  fi
  if echo "$libs" | grep -iE "$pattern"; then
    echo "FAIL: $bin links a library matching '$pattern'" >&2
    status=1
  else
    echo "ok: $bin links nothing matching '$pattern'$([ $direct -eq 1 ] && echo ' directly')"
  fi
done
exit $status
