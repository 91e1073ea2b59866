#!/bin/sh
# Seeds the fuzz corpus with the repository's URDFs (reference robots and test fixtures).
# Run from fuzz/: ./seed.sh
set -eu
corpus=corpus/urdf_to_derivation
mkdir -p "$corpus"
cp ../tests/robots/*.urdf ../codegen/tests/urdf/*.urdf "$corpus"/
find ../codegen/tests/urdf -mindepth 2 -name '*.urdf' -exec cp {} "$corpus"/ \;
echo "seeded $(ls "$corpus" | wc -l) files into $corpus"
