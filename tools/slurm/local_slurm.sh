#!/usr/bin/env bash
# A one-node Slurm on this machine, for trying the job scripts (as root; Debian's
# slurm-wlm and munge; no systemd, no cgroups). Everything lives under STATE; the
# system's /etc/slurm and /etc/munge are not touched.
#   local_slurm.sh start STATE   starts munged, slurmctld and slurmd; prints the
#                                export line that points sbatch and squeue at them
#   local_slurm.sh stop STATE    stops them
set -euo pipefail
cmd=${1:?usage: local_slurm.sh start|stop STATE}
state=$(realpath -m "${2:?usage: local_slurm.sh start|stop STATE}")

stop() {
  for p in slurmd slurmctld munged; do
    [ -f "$state/$p.pid" ] && kill "$(cat "$state/$p.pid")" 2>/dev/null || true
  done
  for p in slurmd slurmctld munged; do
    for _ in $(seq 50); do
      [ -f "$state/$p.pid" ] && kill -0 "$(cat "$state/$p.pid")" 2>/dev/null || break
      sleep 0.1
    done
  done
}

if [ "$cmd" = stop ]; then
  stop
  exit 0
fi
[ "$cmd" = start ] || { echo "usage: local_slurm.sh start|stop STATE" >&2; exit 2; }
[ "$(id -u)" = 0 ] || { echo "local_slurm.sh: run as root" >&2; exit 1; }

mkdir -p "$state"/{munge-key,munge,spool,ctld}
chmod 755 "$state"
chown munge:munge "$state/munge-key" "$state/munge"
chmod 700 "$state/munge-key"
chmod 755 "$state/munge"  # clients (slurmctld, slurmd, sbatch) reach the socket there
dd if=/dev/urandom of="$state/munge-key/munge.key" bs=1024 count=1 status=none
chown munge:munge "$state/munge-key/munge.key"
chmod 400 "$state/munge-key/munge.key"
runuser -u munge -- /usr/sbin/munged --key-file="$state/munge-key/munge.key" --socket="$state/munge/munge.socket" \
  --pid-file="$state/munge/munged.pid" --log-file="$state/munge/munged.log" --seed-file="$state/munge-key/munged.seed"
cp "$state/munge/munged.pid" "$state/munged.pid"

host=$(hostname)
cpus=$(nproc)
cat >"$state/slurm.conf" <<CONF
ClusterName=portalsim
SlurmctldHost=$host(127.0.0.1)
SlurmUser=root
AuthType=auth/munge
CredType=cred/munge
AuthInfo=socket=$state/munge/munge.socket
ProctrackType=proctrack/linuxproc
TaskPlugin=task/none
SelectType=select/cons_tres
SelectTypeParameters=CR_Core
MpiDefault=pmix
StateSaveLocation=$state/ctld
SlurmdSpoolDir=$state/spool
SlurmctldPidFile=$state/slurmctld.pid
SlurmdPidFile=$state/slurmd.pid
SlurmctldLogFile=$state/slurmctld.log
SlurmdLogFile=$state/slurmd.log
SlurmctldPort=6817
SlurmdPort=6818
ReturnToService=2
NodeName=$host NodeAddr=127.0.0.1 CPUs=$cpus State=UNKNOWN
SchedulerParameters=bf_interval=1,sched_interval=2
PartitionName=debug Nodes=ALL Default=YES MaxTime=INFINITE State=UP OverSubscribe=FORCE:4
CONF
export SLURM_CONF=$state/slurm.conf
slurmctld -i -f "$SLURM_CONF"
slurmd -f "$SLURM_CONF"
# Wait for the node to be up.
for _ in $(seq 100); do
  sinfo -h -o %T 2>/dev/null | grep -qE '^(idle|mixed|allocated)' && break
  sleep 0.2
done
sinfo -h -o %T | grep -qE '^(idle|mixed|allocated)' || { echo "local_slurm.sh: the node did not come up; see $state/*.log" >&2; stop; exit 1; }
echo "export SLURM_CONF=$SLURM_CONF"
