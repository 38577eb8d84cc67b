#!/bin/sh
# Builds the C++ transcriptions with g++ -O3 and runs them and the crate's table mode alternately
# (C++, crate, C++, crate), printing ns per call (minimum and median over batches of 1024 calls).
# Run from the crate root: `sh benches/cpp/run.sh [ROUNDS [BATCHES [POOL]]]` (default 5 1000 16;
# POOL blocks of 1024 inputs, batch k on block k mod POOL; 1 repeats one block, see table_common.rs).
# Not part of CI: needs g++; the crate side builds with `cargo bench -p brdf-benches --no-run`.
# Before/after comparisons: set BEFORE_NDF and BEFORE_FRESNEL to bench binaries built from an older
# `src/` (copied out of target/release/deps/ before rebuilding); each pass then runs C++, before,
# crate, with the before rows labelled `before`.
set -e
ROUNDS=${1:-5}
BATCHES=${2:-1000}
POOL=${3:-16}
OUT=target/cpp
mkdir -p "$OUT"
g++ -O3 -fno-math-errno -std=c++17 -o "$OUT/analytic" benches/cpp/analytic.cpp
cargo bench -p brdf-benches --bench ndf --bench fresnel --no-run 2>/dev/null
NDF=$(ls -t target/release/deps/ndf-* | grep -v '\.d$' | head -1)
FRESNEL=$(ls -t target/release/deps/fresnel-* | grep -v '\.d$' | head -1)
echo "# $(uptime)"
echo "# g++ $(g++ -dumpfullversion) -O3 -fno-math-errno; crate: cargo bench (release); pool $POOL"
for pass in 1 2; do
  echo "## pass $pass: C++"
  "$OUT/analytic" "$ROUNDS" "$BATCHES" "$POOL"
  if [ -n "$BEFORE_NDF" ]; then
    echo "## pass $pass: before"
    BRDF_TABLE=1 BRDF_TABLE_POOL=$POOL BRDF_TABLE_ROUNDS=$ROUNDS BRDF_TABLE_BATCHES=$BATCHES "$BEFORE_NDF" | sed 's/ crate    / before   /'
    BRDF_TABLE=1 BRDF_TABLE_POOL=$POOL BRDF_TABLE_ROUNDS=$ROUNDS BRDF_TABLE_BATCHES=$BATCHES "$BEFORE_FRESNEL" | sed 's/ crate    / before   /'
  fi
  echo "## pass $pass: crate"
  BRDF_TABLE=1 BRDF_TABLE_POOL=$POOL BRDF_TABLE_ROUNDS=$ROUNDS BRDF_TABLE_BATCHES=$BATCHES "$NDF"
  BRDF_TABLE=1 BRDF_TABLE_POOL=$POOL BRDF_TABLE_ROUNDS=$ROUNDS BRDF_TABLE_BATCHES=$BATCHES "$FRESNEL"
done
echo "# $(uptime)"
