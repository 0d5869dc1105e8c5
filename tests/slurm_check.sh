#!/usr/bin/env bash
# ctest slurm.local: a one-node Slurm on this machine (tools/slurm/local_slurm.sh) runs
# tools/slurm/generate.sbatch both ways, MPI (3 ranks under srun) and an array of 3
# shards followed by a merge job; each data set must equal one process's, byte for byte.
# Needs root (munged and slurmd), as CI runs.
set -euo pipefail
portalsim=$(realpath "${1:?usage: slurm_check.sh PORTALSIM WORKDIR}")
work=$(realpath -m "${2:?usage: slurm_check.sh PORTALSIM WORKDIR}")
here=$(cd "$(dirname "$0")/.." && pwd)
slurm="$here/tools/slurm"

# The daemons' state lives in a folder of its own under /tmp: munged runs as the munge user,
# which cannot reach it under a build folder inside a folder only root may enter (a clone
# in a mktemp -d folder). $work.slurm-state names it, so that a run cut short is stopped.
marker=$work.slurm-state
if [ -f "$marker" ]; then "$slurm/local_slurm.sh" stop "$(cat "$marker")" 2>/dev/null || true; fi
rm -rf "$work"
mkdir -p "$work"
state=$(mktemp -d /tmp/portalsim-slurm.XXXXXX)
echo "$state" >"$marker"
trap '"$slurm/local_slurm.sh" stop "$state"; rm -rf "$state" "$marker"' EXIT
"$slurm/local_slurm.sh" start "$state" >/dev/null
export SLURM_CONF=$state/slurm.conf PORTALSIM=$portalsim
cd "$work"

spec=(--count 900 --seed 11 --rule gun --what both --format arff,csv,npy,h5 --batch 64)
"$portalsim" generate "${spec[@]}" --quiet --out "$work/one"

# Waits for job ID to end, failing unless it completed (a job whose dependency failed ends
# pending). sbatch --wait looks at 2 s and then at 10 s (its sleeps grow fourfold), so a job
# of 3 s took 10.
wait_job() {
  local line state end=$((SECONDS + 300))
  while [ $SECONDS -lt $end ]; do
    line=$(scontrol -o show job "$1")
    state=$(grep -o 'JobState=[A-Z_]*' <<<"$line" | cut -d= -f2)
    case $state in
      COMPLETED) return 0 ;;
      PENDING | CONFIGURING | RUNNING | COMPLETING)
        if grep -q 'Reason=DependencyNeverSatisfied' <<<"$line"; then
          echo "slurm.local: job $1 waits on a job that failed" >&2
          return 1
        fi
        sleep 0.2
        ;;
      *)
        echo "slurm.local: job $1 ended $state" >&2
        return 1
        ;;
    esac
  done
  echo "slurm.local: job $1 did not end in 300 s" >&2
  return 1
}
# MPI: three ranks on two cores (--overcommit), started by srun inside the job.
wait_job "$(sbatch --parsable --ntasks=3 --overcommit "$slurm/generate.sbatch" "$work/mpi" "${spec[@]}")"
# An array of three shards, then the merge once all three succeeded.
id=$(sbatch --parsable --array=0-2 "$slurm/generate.sbatch" "$work/array" "${spec[@]}")
wait_job "$(sbatch --parsable --dependency=afterok:"$id" "$slurm/generate.sbatch" --merge "$work/array" 3)"

status=0
for d in mpi array; do
  if diff -r "$work/one" "$work/$d" >/dev/null; then
    echo "slurm.local: $d equals one process, byte for byte ($(find "$work/$d" -type f | wc -l) files)"
  else
    echo "slurm.local: $d differs from one process:" >&2
    diff -rq "$work/one" "$work/$d" >&2 || true
    status=1
  fi
done
[ ! -e "$work/array.parts" ] || { echo "slurm.local: the merge job left array.parts behind" >&2; status=1; }
if [ $status -ne 0 ]; then
  echo "--- job logs ---" >&2
  cat "$work"/portalsim-*.out >&2 || true
fi
exit $status
