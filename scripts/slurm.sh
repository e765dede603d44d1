#!/usr/bin/env bash
# Installs and starts a single-node Slurm cluster on this machine (idempotent): Debian's
# slurm-wlm and munge, slurmctld and slurmd on localhost with every core, so that the tests of
# scripts/slurm-generate run a real job array. Needs apt as root; without it the Slurm tests skip
# themselves, except where NPRT_REQUIRE_SLURM=1 (scripts/test sets it after this succeeds).
# Not for a real cluster: there, scripts/slurm-generate runs on what the cluster has.
set -euo pipefail
cluster=nprt-test
# Whether the controller answers with a node that takes jobs (no pipe into grep -q: with
# pipefail, its early exit could fail the pipeline).
node_up() { grep -Eq 'idle|mixed|alloc' <<<"$(timeout 5 sinfo -h -o %T 2>/dev/null || true)"; }
if command -v sinfo >/dev/null && node_up; then
  config="$(scontrol show config 2>/dev/null || true)"
  if grep -Eq "^ClusterName += $cluster\$" <<<"$config"; then
    exit 0
  fi
  # The tests write to this machine's /tmp, which a real cluster's nodes do not share.
  echo "slurm: another Slurm cluster answers here; the tests need this script's single-node one ($cluster)" >&2
  exit 1
fi
if [ "$(id -u)" != 0 ] || ! command -v apt-get >/dev/null; then
  echo "slurm: no running cluster, and apt (as root) is not available to install one" >&2
  exit 1
fi
if ! command -v slurmctld >/dev/null || ! command -v munged >/dev/null; then
  echo "slurm: installing Debian's slurm-wlm and munge" >&2
  log="$(mktemp)"
  trap 'rm -f "$log"' EXIT
  (apt-get update -qq && DEBIAN_FRONTEND=noninteractive apt-get install -y -qq --no-install-recommends \
    slurm-wlm munge) >"$log" 2>&1 || { cat "$log" >&2; exit 1; }
fi

host="$(hostname -s)"
mkdir -p /etc/slurm /var/spool/slurmctld /var/spool/slurmd /var/log/slurm /run/munge
# Memory in MiB as slurmd counts it, so that the node is not drained for having less.
memory="$(awk '/MemTotal/ { print int($2 / 1024 * 0.9) }' /proc/meminfo)"
cat >/etc/slurm/slurm.conf <<EOF
# Written by nprt's scripts/slurm.sh: one node, this machine, for tests.
ClusterName=$cluster
SlurmctldHost=$host(127.0.0.1)
SlurmUser=root
SlurmdUser=root
AuthType=auth/munge
ProctrackType=proctrack/linuxproc
TaskPlugin=task/none
SelectType=select/cons_tres
SelectTypeParameters=CR_Core
SchedulerType=sched/backfill
JobAcctGatherType=jobacct_gather/none
AccountingStorageType=accounting_storage/none
MpiDefault=none
ReturnToService=2
JobRequeue=1
MinJobAge=600
StateSaveLocation=/var/spool/slurmctld
SlurmdSpoolDir=/var/spool/slurmd
SlurmctldPidFile=/run/slurmctld.pid
SlurmdPidFile=/run/slurmd.pid
SlurmctldLogFile=/var/log/slurm/slurmctld.log
SlurmdLogFile=/var/log/slurm/slurmd.log
NodeName=$host NodeAddr=127.0.0.1 CPUs=$(nproc) RealMemory=$memory State=UNKNOWN
PartitionName=debug Nodes=$host Default=YES MaxTime=INFINITE State=UP
EOF
chown munge:munge /run/munge
pgrep -x munged >/dev/null || runuser -u munge -- munged
pgrep -x slurmctld >/dev/null || slurmctld
pgrep -x slurmd >/dev/null || slurmd
for _ in $(seq 60); do
  if node_up; then
    echo "slurm: single-node cluster up on $host ($(nproc) cores)" >&2
    exit 0
  fi
  sleep 0.5
done
echo "slurm: the cluster did not come up; see /var/log/slurm/" >&2
sinfo >&2 || true
tail -5 /var/log/slurm/slurmctld.log /var/log/slurm/slurmd.log >&2 || true
exit 1
