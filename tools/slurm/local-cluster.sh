#!/usr/bin/env bash
# A throw-away single-node Slurm cluster on this machine, for the farm's test
# (tests/farm/slurm_test.sh), its figures (tools/bench_farm.sh) and for trying
# tools/slurm/submit.sh without a cluster (docs/farm.md).
#
#   tools/slurm/local-cluster.sh start DIR   configure and start munged, slurmctld, slurmd
#   tools/slurm/local-cluster.sh stop DIR    cancel its jobs, stop the daemons by their PIDs
#
# Everything lives in DIR (configuration, state, spool, logs, munge socket);
# nothing under /etc is changed. Clients find the cluster through
# SLURM_CONF=DIR/slurm.conf, which `start` prints as an export line.
# Needs root and Debian's slurm-wlm and munge (tools/install-deps.sh), and
# neither systemd nor cgroups: process tracking is proctrack/linuxproc and
# task/none. The node has this machine's CPUs and memory.
set -euo pipefail

fail() {
  echo "local-cluster.sh: error: $*" >&2
  exit 1
}

usage() {
  echo "usage: tools/slurm/local-cluster.sh start|stop DIR" >&2
  exit 2
}

# Two TCP ports nothing listens on (the daemons' default ports may be taken by
# a real Slurm): random ones from 20000-59999, each checked by connecting.
free_ports() {
  local ports=() port
  while ((${#ports[@]} < 2)); do
    port=$((20000 + RANDOM % 40000))
    [[ " ${ports[*]} " != *" $port "* ]] || continue
    if ! (exec 3<>"/dev/tcp/127.0.0.1/$port") 2>/dev/null; then ports+=("$port"); fi
  done
  echo "${ports[*]}"
}

write_config() {
  local dir=$1 host=$2 ctld_port=$3 slurmd_port=$4
  local cpus memory_mib
  cpus=$(nproc)
  memory_mib=$(($(awk '/^MemTotal:/ { print $2 }' /proc/meminfo) / 1024 * 9 / 10))
  cat >"$dir/slurm.conf" <<EOF
# Written by tools/slurm/local-cluster.sh: a single-node cluster in $dir.
ClusterName=vkrt-local
SlurmctldHost=$host(127.0.0.1)
SlurmctldPort=$ctld_port
SlurmdPort=$slurmd_port
SlurmUser=root
AuthType=auth/munge
AuthInfo=socket=$dir/munge/munge.socket
CredType=cred/munge
StateSaveLocation=$dir/state
SlurmdSpoolDir=$dir/spool
SlurmctldPidFile=$dir/run/slurmctld.pid
SlurmdPidFile=$dir/run/slurmd.pid
SlurmctldLogFile=$dir/log/slurmctld.log
SlurmdLogFile=$dir/log/slurmd.log
ProctrackType=proctrack/linuxproc
TaskPlugin=task/none
SelectType=select/cons_tres
SelectTypeParameters=CR_CPU
AccountingStorageType=accounting_storage/none
JobAcctGatherType=jobacct_gather/none
JobCompType=jobcomp/none
MpiDefault=none
MailProg=/bin/true
SchedulerParameters=batch_sched_delay=0,sched_min_interval=0
ReturnToService=2
MinJobAge=600
NodeName=$host NodeAddr=127.0.0.1 CPUs=$cpus RealMemory=$memory_mib State=UNKNOWN
PartitionName=local Nodes=$host Default=YES MaxTime=INFINITE State=UP
EOF
}

start_munged() {
  local dir=$1
  mkdir -p "$dir/munge"
  chown munge:munge "$dir/munge"
  chmod 0755 "$dir/munge"
  setpriv --reuid=munge --regid=munge --init-groups test -w "$dir/munge" ||
    fail "user munge cannot reach $dir/munge: every folder above it must be searchable by others (chmod o+x)"
  # munged refuses to run as root; --force lets it accept the temporary folder's /tmp parent.
  setpriv --reuid=munge --regid=munge --init-groups /usr/sbin/munged --foreground --force \
    --socket="$dir/munge/munge.socket" --pid-file="$dir/munge/munged.pid" \
    --log-file="$dir/munge/munged.log" --seed-file="$dir/munge/munged.seed" \
    >>"$dir/log/munged.out" 2>&1 &
  echo $! >"$dir/run/munged.started"
  local tries
  for ((tries = 0; tries < 100; ++tries)); do
    [[ -S $dir/munge/munge.socket ]] && return 0
    kill -0 "$(cat "$dir/run/munged.started")" 2>/dev/null || break
    sleep 0.1
  done
  fail "munged did not start; see $dir/munge/munged.log and $dir/log/munged.out"
}

start_daemon() {
  local dir=$1 name=$2
  "/usr/sbin/$name" -D -f "$dir/slurm.conf" >>"$dir/log/$name.out" 2>&1 &
  echo $! >"$dir/run/$name.started"
}

wait_for_idle_node() {
  local dir=$1 state tries
  for ((tries = 0; tries < 300; ++tries)); do
    state=$(SLURM_CONF=$dir/slurm.conf sinfo -h -o %T 2>/dev/null | head -n 1 || true)
    [[ $state == idle ]] && return 0
    for name in slurmctld slurmd; do
      kill -0 "$(cat "$dir/run/$name.started")" 2>/dev/null ||
        fail "$name exited; see $dir/log/$name.log and $dir/log/$name.out"
    done
    sleep 0.1
  done
  fail "the node is not idle after 30 s (state '${state:-none}'); see $dir/log/"
}

start() {
  local dir=$1
  [[ $(id -u) -eq 0 ]] || fail "needs root (slurmd runs jobs as their submitting user, and munged runs as user munge)"
  for program in /usr/sbin/munged /usr/sbin/slurmctld /usr/sbin/slurmd sbatch sinfo; do
    command -v "$program" >/dev/null || fail "$program not found: install slurm-wlm and munge (tools/install-deps.sh)"
  done
  [[ ! -e $dir/run ]] || fail "$dir already holds a cluster (stop it first: tools/slurm/local-cluster.sh stop $dir)"
  mkdir -p "$dir"/{state,spool,log,run}
  chmod 0755 "$dir"
  local host ports
  host=$(hostname -s)
  ports=$(free_ports)
  write_config "$dir" "$host" ${ports}
  start_munged "$dir"
  start_daemon "$dir" slurmctld
  start_daemon "$dir" slurmd
  wait_for_idle_node "$dir"
  echo "export SLURM_CONF=$dir/slurm.conf"
}

# Stops one daemon by its recorded PID: TERM, then KILL after 10 s.
stop_daemon() {
  local pid_file=$1 pid tries
  [[ -f $pid_file ]] || return 0
  pid=$(cat "$pid_file")
  if kill -0 "$pid" 2>/dev/null; then
    kill -TERM "$pid" 2>/dev/null || true
    for ((tries = 0; tries < 100; ++tries)); do
      kill -0 "$pid" 2>/dev/null || break
      sleep 0.1
    done
    kill -KILL "$pid" 2>/dev/null || true
  fi
  rm -f "$pid_file"
}

stop() {
  local dir=$1
  [[ -d $dir/run ]] || return 0
  if [[ -f $dir/run/slurmctld.started ]] && kill -0 "$(cat "$dir/run/slurmctld.started")" 2>/dev/null; then
    SLURM_CONF=$dir/slurm.conf scancel --full --quiet --user=root 2>/dev/null || true
  fi
  # slurmd first (it reaps its job steps), then the controller, then munge.
  stop_daemon "$dir/run/slurmd.started"
  stop_daemon "$dir/run/slurmctld.started"
  stop_daemon "$dir/run/munged.started"
  rmdir "$dir/run" 2>/dev/null || true
}

(($# == 2)) || usage
case $1 in
  start) start "$2" ;;
  stop) stop "$2" ;;
  *) usage ;;
esac
