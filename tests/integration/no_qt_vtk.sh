#!/usr/bin/env bash
# Fails when any given binary links a Qt or VTK library.
set -u
status=0
for bin in "$@"; do
  if ldd "$bin" | grep -iE 'libQt|libvtk'; then
    echo "FAIL: $bin links Qt or VTK" >&2
    status=1
  else
    echo "ok: $bin links neither Qt nor VTK"
  fi
done
exit $status
