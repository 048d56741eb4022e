#!/bin/sh
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
