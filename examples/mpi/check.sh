#!/bin/sh
# SPDX-License-Identifier: MIT
# make check-mpi: run the MPI examples; each one compares its distributed
# result with the serial fold of the same data and exits nonzero if they
# disagree.  Usage: check.sh BUILD_DIR "MPIRUN COMMAND"
set -eu
B=$1
MPIRUN=$2
if [ "$(id -u)" = 0 ]; then
  # Open MPI refuses root unless told twice (flag and environment).
  export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1
fi
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
echo "-- generated stream, sharded by rank"
$MPIRUN "$B/mpi/meanvar_mpi"
echo "-- a NaN in the last rank's shard: reported at its global index"
$MPIRUN "$B/mpi/meanvar_mpi" -nan 999000
echo "-- fewer observations than ranks"
$MPIRUN "$B/mpi/meanvar_mpi" -n 1
echo "-- a file, each rank reading its own slice"
$MPIRUN "$B/mpi/meanvar_mpi" -write "$tmp/x.f64" 300007
$MPIRUN "$B/mpi/meanvar_mpi" "$tmp/x.f64"
echo "-- calibration: moments merged, the root fits the ellipsoid"
$MPIRUN "$B/mpi/calibrate_mpi"
echo "-- calibration: a NaN in the last rank's shard"
$MPIRUN "$B/mpi/calibrate_mpi" -nan 150000
echo "-- calibration: fewer samples than ranks (the fit refuses, as serially)"
$MPIRUN "$B/mpi/calibrate_mpi" -n 1
echo "-- least squares: normal equations travel with their storage, the root solves"
$MPIRUN "$B/mpi/lsq_mpi"
$MPIRUN "$B/mpi/lsq_mpi" -nan 300000
echo "-- discovery: block Gram matrices merged in rank order, the root ranks and selects"
$MPIRUN "$B/mpi/discover_mpi"
$MPIRUN "$B/mpi/discover_mpi" -nan 150000
echo "-- discovery: the second recording begins exactly at the cut between ranks"
$MPIRUN "$B/mpi/discover_mpi" -n 100001
