# Settings shared by parallel.sh and slurm.sh (sourced), with their defaults:
#   WARPLIGHT  the warplight binary [warplight]
#   TABLES     table addresses [fabianowski:all]
#   PROTOCOL   quick or thesis [thesis]
#   FRAMES     frames of the protocol's flights [50 for thesis, 3 for quick]
#   OUT        directory for shard-*.json, logs and the merged tables.md [shards]
#   EXTRA      more `warplight tables` options, e.g. "--scenes sponza" []
# shellcheck shell=bash disable=SC2034 # read by the scripts that source it
WARPLIGHT=${WARPLIGHT:-warplight}
TABLES=${TABLES:-fabianowski:all}
PROTOCOL=${PROTOCOL:-thesis}
case $PROTOCOL in thesis) default_frames=50 ;; *) default_frames=3 ;; esac
FRAMES=${FRAMES:-$default_frames}
OUT=${OUT:-shards}
EXTRA=${EXTRA:-}

# frames of shard $1 of $2: "A..B", or nothing when it has none
shard_range() {
  local a=$(($1 * FRAMES / $2)) b=$((($1 + 1) * FRAMES / $2))
  if [ "$a" -lt "$b" ]; then echo "$a..$b"; fi
}
