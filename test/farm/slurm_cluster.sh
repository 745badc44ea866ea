#!/bin/bash
# A single-node Slurm cluster in a temporary folder, for augocc's farm test and perf script
# (test/farm/slurm_test.sh, perf/farm_speedup.sh). Source it, then:
#   cluster_start DIR   munged, slurmctld, slurmd started in the foreground as background jobs of
#                       this shell (their process ids in CLUSTER_PIDS), state and logs in DIR,
#                       SLURM_CONF exported; returns when the node is idle.
#   cluster_wait        waits until no job is queued or running.
#   cluster_stop        stops exactly what cluster_start started, by process id.
# The node is this machine by its short host name, cgroup-free (proctrack/linuxproc, task/none),
# no accounting; ports 16817-16818 so that a real Slurm on the machine is not disturbed.

CLUSTER_PIDS=()

cluster_have_slurm() {
    command -v munged >/dev/null && command -v slurmctld >/dev/null &&
        command -v slurmd >/dev/null && command -v sbatch >/dev/null
}

cluster_start() {
    local dir=$1 host cpus i
    host=$(hostname -s)
    cpus=$(nproc)
    mkdir -p "$dir/munge" "$dir/state" "$dir/spool" "$dir/log"
    chmod 0700 "$dir/munge"
    dd if=/dev/urandom of="$dir/munge/munge.key" bs=1024 count=1 status=none
    chmod 0400 "$dir/munge/munge.key"
    cat >"$dir/slurm.conf" <<CONF
ClusterName=augocctest
SlurmctldHost=$host
SlurmctldPort=16817
SlurmdPort=16818
SlurmUser=root
SlurmdUser=root
AuthType=auth/munge
AuthInfo=socket=$dir/munge/munge.socket
CredType=cred/munge
StateSaveLocation=$dir/state
SlurmdSpoolDir=$dir/spool
SlurmctldPidFile=$dir/slurmctld.pid
SlurmdPidFile=$dir/slurmd.pid
SlurmctldLogFile=$dir/log/slurmctld.log
SlurmdLogFile=$dir/log/slurmd.log
ProctrackType=proctrack/linuxproc
TaskPlugin=task/none
JobAcctGatherType=jobacct_gather/none
AccountingStorageType=accounting_storage/none
JobCompType=jobcomp/none
SelectType=select/cons_tres
SelectTypeParameters=CR_Core
SchedulerType=sched/backfill
MpiDefault=none
ReturnToService=2
SlurmdTimeout=30
NodeName=$host CPUs=$cpus State=UNKNOWN
PartitionName=farmtest Nodes=$host Default=YES MaxTime=INFINITE State=UP
CONF
    export SLURM_CONF=$dir/slurm.conf
    munged --foreground --force --key-file="$dir/munge/munge.key" \
        --socket="$dir/munge/munge.socket" --pid-file="$dir/munge/munged.pid" \
        --log-file="$dir/log/munged.log" --seed-file="$dir/munge/munged.seed" \
        >"$dir/log/munged.stdout" 2>&1 &
    CLUSTER_PIDS+=($!)
    for i in $(seq 50); do
        [ -S "$dir/munge/munge.socket" ] && break
        sleep 0.1
    done
    slurmctld -D -i -f "$SLURM_CONF" >"$dir/log/slurmctld.stdout" 2>&1 &
    CLUSTER_PIDS+=($!)
    slurmd -D -f "$SLURM_CONF" >"$dir/log/slurmd.stdout" 2>&1 &
    CLUSTER_PIDS+=($!)
    for i in $(seq 300); do
        if [ "$(sinfo --noheader --format=%T 2>/dev/null)" = idle ]; then
            return 0
        fi
        sleep 0.2
    done
    echo "slurm_cluster: the node did not become idle in 60 s; logs in $dir/log" >&2
    return 1
}

cluster_wait() {
    local timeout=${1:-600} i
    for i in $(seq $((timeout * 5))); do
        if [ -z "$(squeue --noheader --format=%i)" ]; then
            return 0
        fi
        sleep 0.2
    done
    echo "slurm_cluster: jobs still queued after $timeout s" >&2
    squeue >&2
    return 1
}

cluster_stop() {
    local pid i
    # Daemons in reverse order of their start (slurmd, slurmctld, munged), by process id.
    for ((i = ${#CLUSTER_PIDS[@]} - 1; i >= 0; i--)); do
        pid=${CLUSTER_PIDS[i]}
        kill "$pid" 2>/dev/null || true
        wait "$pid" 2>/dev/null || true
    done
    CLUSTER_PIDS=()
}
