#!/usr/bin/env bash
# A campaign split into shards run by GNU parallel, locally or across hosts
# (docs/campaign.md, "Scale-out"), then merged into one folder.
#   tools/campaign_parallel.sh OUT SHARDS [parallel options] -- [stewart_campaign options]
# e.g.
#   tools/campaign_parallel.sh runs/c 4 -j 2 -- --runs 1000 --scenario paper
#   tools/campaign_parallel.sh runs/c 8 --sshlogin 4/host1,4/host2 --workdir . -- --runs 8000
# Each shard runs single-threaded (--jobs 1): parallel places the shards on the
# cores. With --sshlogin, every host needs this checkout built at the same
# path, and OUT must be on a file system all hosts share (NFS): the shards
# write there and the merge reads there.
set -euo pipefail
ROOT=$(cd "$(dirname "$0")/.." && pwd)
[[ $# -ge 2 ]] || { sed -n '2,11p' "$0" >&2; exit 2; }
OUT=$(realpath -m "$1") SHARDS=$2
shift 2
PARALLEL_ARGS=()
while (($#)) && [[ $1 != -- ]]; do PARALLEL_ARGS+=("$1"); shift; done
[[ ${1:-} == -- ]] && shift
command -v parallel >/dev/null || { echo "campaign_parallel: GNU parallel missing (tools/setup.sh installs it)" >&2; exit 2; }
[[ $SHARDS =~ ^[1-9][0-9]*$ ]] || { echo "campaign_parallel: SHARDS must be a positive integer" >&2; exit 2; }
BIN=${STEWART_BUILD_DIR:-$ROOT/build}/tools/stewart_campaign
mkdir -p "$OUT"
# One shard per job; each writes OUT/shard_K, its own progress to its log.
seq 1 "$SHARDS" | parallel --will-cite --halt now,fail=1 "${PARALLEL_ARGS[@]}" \
  "$BIN" "$@" --jobs 1 --no-plots --shard "{}/$SHARDS" --out "$OUT/shard_{}" \
  ">" "$OUT/shard_{}.log" "2>&1"
shards=()
for k in $(seq 1 "$SHARDS"); do shards+=("$OUT/shard_$k"); done
exec "$BIN" --merge "${shards[@]}" --out "$OUT"
