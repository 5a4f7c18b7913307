#!/usr/bin/env bash
# Submits a sweep as a Slurm job array (scripts/slurm/sweep.sbatch, one shard per task) and a merge
# job that runs when every task has succeeded (--dependency=afterok). Prints the merge job's id.
#   usage: submit.sh OUT N SCENARIO [sweep options...]    (QUADCOSIM names the binary)
# Extra sbatch options (partition, account, time) go in SBATCH_ARGS, e.g. SBATCH_ARGS="-p short".
# OUT, SCENARIO and a QUADCOSIM path may be relative to the current directory: they are made absolute
# here, as the jobs run in OUT (--chdir); the shards' header (so summary.json) holds the absolute SCENARIO.
set -euo pipefail
if [ $# -lt 3 ]; then
  echo "usage: submit.sh OUT N SCENARIO [sweep options...]" >&2
  exit 2
fi
OUT=$(realpath -m "$1")
N=$2
if [ ! -f "$3" ]; then
  echo "submit.sh: scenario $3 is not a file (from $PWD)" >&2
  exit 2
fi
SCENARIO=$(realpath "$3")
shift 3
QC=${QUADCOSIM:-quadcosim}
case "$QC" in */*) QC=$(realpath "$QC") ;; esac  # a path (not a name on PATH) is relative to here too
HERE=$(dirname "$(realpath "$0")")
mkdir -p "$OUT"
# shellcheck disable=SC2086
array=$(sbatch --parsable ${SBATCH_ARGS:-} --array="1-$N" --chdir="$OUT" --export=ALL,QUADCOSIM="$QC" \
        "$HERE/sweep.sbatch" "$OUT" "$N" "$SCENARIO" "$@")
array=${array%%;*}
shards=()
for k in $(seq 1 "$N"); do shards+=("$OUT/shard-$k"); done
# Merge exit 1 (pass rate below --min-pass-rate) is a verdict, not a failure of the job.
# shellcheck disable=SC2086
merge=$(sbatch --parsable ${SBATCH_ARGS:-} --dependency="afterok:$array" --chdir="$OUT" --job-name=quadcosim-merge \
        --output="$OUT/merge.out" --wrap "'$QC' sweep merge '$OUT/merged' ${shards[*]} --no-plots --min-pass-rate 0")
echo "${merge%%;*}"
