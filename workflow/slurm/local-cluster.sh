#!/usr/bin/env bash
# A one-node SLURM cluster on this machine, for testing the slurm profile (tests/slurm/).
#
#   workflow/slurm/local-cluster.sh up       write the configs, start munged, MariaDB, slurmdbd, slurmctld, slurmd
#   workflow/slurm/local-cluster.sh status   which of those run, and sinfo
#   workflow/slurm/local-cluster.sh down     stop exactly the processes `up` started (their saved PIDs)
#
# Installs nothing. Needs root (the daemons run as root; /etc/slurm/ gets symlinks to the generated configs,
# where every SLURM command looks) and the Debian packages:
#   apt-get install slurm-wlm munge slurmdbd mariadb-server
# Accounting (slurmdbd on a private MariaDB) is on because the Snakemake executor plugin asks sacct for job
# states whenever sacct exists. State, logs, PIDs and the database live in $EFISH_SLURM_DIR (default
# .slurm-local/ in the repository, git-ignored); one node with this machine's cores and memory, one
# partition `debug`.
set -euo pipefail

HERE="${BASH_SOURCE[0]%/*}"
[[ $HERE == "${BASH_SOURCE[0]}" ]] && HERE=.
REPO="$(cd "$HERE/../.." && pwd)"  # shell builtins only until the tools are checked
DIR="${EFISH_SLURM_DIR:-$REPO/.slurm-local}"
DB_PORT="${EFISH_SLURM_DB_PORT:-33306}"  # a private port: never the system's MariaDB on 3306
ETC=/etc/slurm
# start order; `down` stops in reverse
DAEMONS=(munged mariadbd slurmdbd slurmctld slurmd)

die() { echo "local-cluster: $*" >&2; exit 1; }
say() { echo "local-cluster: $*"; }

check_installed() {
    local missing=()
    for cmd in munged munge unmunge mariadbd mariadb-install-db mariadb slurmdbd slurmctld slurmd sinfo sacct \
               sacctmgr scontrol setpriv setsid hostname nproc free; do
        command -v "$cmd" >/dev/null 2>&1 || missing+=("$cmd")
    done
    if ((${#missing[@]})); then
        die "missing ${missing[*]}: install them with apt-get install slurm-wlm munge slurmdbd mariadb-server"
    fi
    [[ $EUID -eq 0 ]] || die "run as root: the daemons run as root and $ETC/ gets links to the generated configs"
}

pid_of() { cat "$DIR/pids/$1" 2>/dev/null || true; }

alive() {  # alive NAME: the saved PID runs the named program
    local pid; pid="$(pid_of "$1")"
    [[ -n $pid ]] && kill -0 "$pid" 2>/dev/null && [[ "$(cat "/proc/$pid/comm" 2>/dev/null)" == "$1"* ]]
}

start() {  # start NAME COMMAND...: run in its own session, output to NAME.out, PID saved
    local name=$1; shift
    setsid "$@" >"$DIR/logs/$name.out" 2>&1 < /dev/null &
    echo $! >"$DIR/pids/$name"
}

wait_for() {  # wait_for SECONDS DESCRIPTION COMMAND...: poll until the command succeeds
    local seconds=$1 what=$2; shift 2
    for ((i = 0; i < seconds * 5; i++)); do
        "$@" >/dev/null 2>&1 && return 0
        sleep 0.2
    done
    die "$what did not come up within ${seconds}s; see $DIR/logs/"
}

write_configs() {
    local cpus mem
    cpus="$(nproc)"
    mem="$(free -m | awk '/^Mem:/ {print $2}')"
    mem=$((mem > 3000 ? mem - 2000 : 1000))  # leave the OS and the daemons about 2 GB
    mkdir -p "$DIR"/{state,spool,logs,pids,mysql}
    cat >"$DIR/slurm.conf" <<EOF
# written by workflow/slurm/local-cluster.sh: one node ($cpus CPUs, $mem MB), one partition
ClusterName=efish
SlurmctldHost=$NODE
SlurmUser=root
SlurmdUser=root
AuthType=auth/munge
ProctrackType=proctrack/linuxproc
TaskPlugin=task/none
SelectType=select/cons_tres
SelectTypeParameters=CR_Core_Memory
ReturnToService=2
MinJobAge=300
StateSaveLocation=$DIR/state
SlurmdSpoolDir=$DIR/spool
SlurmctldPidFile=$DIR/slurmctld.pid
SlurmdPidFile=$DIR/slurmd.pid
SlurmctldLogFile=$DIR/logs/slurmctld.log
SlurmdLogFile=$DIR/logs/slurmd.log
JobAcctGatherType=jobacct_gather/none
AccountingStorageType=accounting_storage/slurmdbd
AccountingStorageHost=localhost
AccountingStoreFlags=job_comment
JobCompType=jobcomp/none
MailProg=/bin/true
DefMemPerCPU=1000
NodeName=$NODE CPUs=$cpus RealMemory=$mem State=UNKNOWN
PartitionName=debug Nodes=ALL Default=YES MaxTime=INFINITE State=UP
EOF
    umask 077  # slurmdbd refuses a readable slurmdbd.conf (it holds the database password)
    cat >"$DIR/slurmdbd.conf" <<EOF
# written by workflow/slurm/local-cluster.sh
DbdHost=localhost
SlurmUser=root
AuthType=auth/munge
LogFile=$DIR/logs/slurmdbd.log
PidFile=$DIR/slurmdbd.pid
StorageType=accounting_storage/mysql
StorageHost=127.0.0.1
StoragePort=$DB_PORT
StorageUser=slurm
StoragePass=efish-local
StorageLoc=slurm_acct_db
EOF
    umask 022
}

link_configs() {  # /etc/slurm/<name> -> ours; never replace a file that is not our link (a real cluster's)
    mkdir -p "$ETC"
    for name in slurm.conf slurmdbd.conf; do
        local target="$ETC/$name"
        if [[ -e $target || -L $target ]] && [[ "$(readlink "$target")" != "$DIR/$name" ]]; then
            die "$target exists and is not this cluster's: move it away (a real cluster's config?) and retry"
        fi
        ln -sfn "$DIR/$name" "$target"
    done
}

start_munge() {
    if munge -n 2>/dev/null | unmunge >/dev/null 2>&1; then
        say "munged already runs (not ours; left alone)"
        return
    fi
    [[ -f /etc/munge/munge.key ]] || die "no /etc/munge/munge.key: reinstall munge (its install creates the key)"
    mkdir -p /run/munge && chown munge:munge /run/munge
    start munged setpriv --reuid=munge --regid=munge --init-groups munged --foreground
    wait_for 10 munged bash -c 'munge -n | unmunge'
}

start_db() {
    local sock="$DIR/mysql.sock"
    if [[ ! -d $DIR/mysql/mysql ]]; then
        mariadb-install-db --no-defaults --datadir="$DIR/mysql" --user=root \
            --auth-root-authentication-method=normal >"$DIR/logs/mariadb-install.out" 2>&1 \
            || die "mariadb-install-db failed; see $DIR/logs/mariadb-install.out"
    fi
    start mariadbd mariadbd --no-defaults --datadir="$DIR/mysql" --socket="$sock" --port="$DB_PORT" \
        --bind-address=127.0.0.1 --user=root --pid-file="$DIR/mariadbd.pid" --log-error="$DIR/logs/mariadbd.log"
    wait_for 60 MariaDB mariadb --no-defaults --socket="$sock" -uroot -e "SELECT 1"
    mariadb --no-defaults --socket="$sock" -uroot <<'EOF'
CREATE DATABASE IF NOT EXISTS slurm_acct_db;
CREATE USER IF NOT EXISTS 'slurm'@'localhost' IDENTIFIED BY 'efish-local';
CREATE USER IF NOT EXISTS 'slurm'@'127.0.0.1' IDENTIFIED BY 'efish-local';
GRANT ALL ON slurm_acct_db.* TO 'slurm'@'localhost';
GRANT ALL ON slurm_acct_db.* TO 'slurm'@'127.0.0.1';
EOF
}

node_ready() { sinfo -h -n "$NODE" -o %T | grep -Eq '^(idle|mixed|allocated)'; }

up() {
    check_installed
    NODE="$(hostname -s)"
    for name in "${DAEMONS[@]}"; do
        alive "$name" && die "$name of this cluster already runs (pid $(pid_of "$name")): run down first"
    done
    write_configs
    link_configs
    start_munge
    start_db
    start slurmdbd slurmdbd -D
    wait_for 60 slurmdbd sacctmgr -n show cluster
    start slurmctld slurmctld -D
    wait_for 60 slurmctld scontrol ping
    start slurmd slurmd -D
    for _ in 1 2 3; do  # a node left down or drained by an earlier run comes back
        node_ready && break
        sleep 3
        scontrol update nodename="$NODE" state=resume >/dev/null 2>&1 || true
    done
    wait_for 60 "node $NODE" node_ready
    say "up: partition debug, node $NODE ($(nproc) CPUs); logs in $DIR/logs"
}

down() {
    local stopped=0
    for ((i = ${#DAEMONS[@]} - 1; i >= 0; i--)); do
        local name=${DAEMONS[i]} pid
        pid="$(pid_of "$name")"
        if alive "$name"; then
            kill -TERM "$pid"
            for _ in $(seq 150); do kill -0 "$pid" 2>/dev/null || break; sleep 0.2; done
            kill -0 "$pid" 2>/dev/null && die "$name (pid $pid) did not stop within 30 s"
            stopped=$((stopped + 1))
        fi
        rm -f "$DIR/pids/$name"
    done
    for name in slurm.conf slurmdbd.conf; do
        [[ "$(readlink "$ETC/$name" 2>/dev/null)" == "$DIR/$name" ]] && rm -f "$ETC/$name"
    done
    say "down: stopped $stopped processes"
}

status() {
    local running=0
    for name in "${DAEMONS[@]}"; do
        if alive "$name"; then
            say "$name runs (pid $(pid_of "$name"))"
            running=$((running + 1))
        else
            say "$name does not run (from this cluster)"
        fi
    done
    if alive slurmctld; then sinfo; fi
    # exit 0 only when the whole cluster runs (munged may be the system's)
    alive slurmctld && alive slurmd && alive slurmdbd && alive mariadbd
}

case "${1:-}" in
    up) up ;;
    down) down ;;
    status) status ;;
    *) echo "usage: $0 up|down|status" >&2; exit 2 ;;
esac
