#!/bin/sh
# tests/slurm/recipes.sh: the Slurm recipes of docs/batch.md, run as written
# (taken from the file) against a real single-node Slurm on localhost:
# munged with its own key and socket, slurmctld and slurmd with a generated
# slurm.conf, all in a temporary directory, stopped (by their pids) and
# removed at the end. The sweep array's task 3 is cancelled (scancel) while
# it runs: the submission fails and `mech merge` says "shard 3/8 missing";
# the repair recipe (sbatch --array=3) reruns just that task, which
# continues its partial file, and the merge equals the unsharded run. The
# batch array's task 1 is cancelled too and repaired (sbatch --array=1, which
# solves only the files with no CSV yet); its merged table equals one batch's.
# Needs root and the Debian
# packages slurm-wlm and munge.
# Run from the repository root:  MECH=build/mech sh tests/slurm/recipes.sh
NAME=slurm . tests/lib.sh
. tests/recipe.sh

for c in munged slurmctld slurmd sbatch scancel squeue sinfo scontrol; do
    if ! command -v $c >/dev/null 2>&1; then
        echo "slurm: $c not found (Debian packages slurm-wlm and munge)" >&2
        exit 2
    fi
done

# ---- a single-node Slurm in $sl -------------------------------------------
sl=$tmp/slurm
mkdir -p "$sl/state" "$sl/spool" "$sl/log"
port=$((17000 + ($$ % 400) * 2))  # two ports of our own: other tests may run a Slurm
stop_slurm() {
    [ -n "$SLURM_CONF" ] && scontrol shutdown >/dev/null 2>&1
    for f in slurmd slurmctld munged; do  # by pid, in case shutdown did not reach them
        p=$(cat "$sl/$f.pid" 2>/dev/null)
        [ -n "$p" ] && kill "$p" 2>/dev/null
    done
    sleep 1
    rm -rf "$tmp"
}
trap stop_slurm EXIT
head -c 1024 /dev/urandom >"$sl/munge.key"
chmod 600 "$sl/munge.key"
munged -f --socket="$sl/munge.sock" --key-file="$sl/munge.key" --log-file="$sl/log/munged.log" \
    --pid-file="$sl/munged.pid" --seed-file="$sl/munged.seed" || { echo "slurm: munged did not start" >&2; exit 2; }
cat >"$sl/slurm.conf" <<CONF
ClusterName=mechtest
SlurmctldHost=localhost(127.0.0.1)
SlurmctldPort=$port
SlurmdPort=$((port + 1))
SlurmUser=root
SlurmdUser=root
AuthType=auth/munge
AuthInfo=socket=$sl/munge.sock
CredType=cred/munge
StateSaveLocation=$sl/state
SlurmdSpoolDir=$sl/spool
SlurmctldPidFile=$sl/slurmctld.pid
SlurmdPidFile=$sl/slurmd.pid
SlurmctldLogFile=$sl/log/slurmctld.log
SlurmdLogFile=$sl/log/slurmd.log
ProctrackType=proctrack/linuxproc
TaskPlugin=task/affinity
JobAcctGatherType=jobacct_gather/none
AccountingStorageType=accounting_storage/none
JobCompType=jobcomp/none
SelectType=select/cons_tres
SelectTypeParameters=CR_CPU
ReturnToService=2
MpiDefault=none
NodeName=mechnode NodeAddr=127.0.0.1 NodeHostname=localhost CPUs=$(nproc) State=UNKNOWN
PartitionName=mech Nodes=mechnode Default=YES MaxTime=INFINITE State=UP
CONF
export SLURM_CONF=$sl/slurm.conf
slurmctld -f "$SLURM_CONF" -i || { echo "slurm: slurmctld did not start" >&2; exit 2; }
slurmd -f "$SLURM_CONF" -N mechnode || { echo "slurm: slurmd did not start" >&2; exit 2; }
for i in $(seq 60); do
    [ "$(sinfo -h -o %t 2>/dev/null)" = idle ] && break
    sleep 0.5
done
[ "$(sinfo -h -o %t 2>/dev/null)" = idle ] && pass ||
    { fail "the node is not idle: $(sinfo 2>&1; tail -n 5 "$sl/log/slurmctld.log")"; exit 1; }

# Cancel task $3 of the array job named $2 once its partial output $1
# is there with its head (the task runs; a sweep's rows come in blocks up to
# a second apart) (waits up to 60 s; gives up when the task finished first,
# its output without .partial existing). Sets cancelled to 1 when it did.
cancel_when_running() {
    cancelled=
    for i in $(seq 1200); do
        if [ -f "$1" ] && [ "$(wc -l <"$1")" -ge 2 ]; then
            job=$(squeue -h -n "$2" -o %F | head -n 1)
            scancel "${job}_$3" && cancelled=1
            return
        fi
        [ -f "${1%.partial}" ] && return
        sleep 0.05
    done
}

# After the submission whose merge step exited $1 with shard $2 (K/M)
# cancelled: non-zero exit, the shard named missing, $3 not written.
merge_refused() {
    if [ -n "$cancelled" ]; then
        [ "$1" -ne 0 ] && pass || fail "the submission with shard $2 cancelled exits 0"
        has_line "$tmp/err" "^mech merge: shard $2 missing" "merge after shard $2 was cancelled"
        [ ! -e "$3" ] && pass || fail "merge wrote $3 with shard $2 missing"
    else
        fail "shard $2 was not seen running, so not cancelled (status $1: $(head -n 3 "$tmp/err"))"
    fi
}

# ---- the sweep array, task 3 cancelled, repaired ----------------------------
scratch
cd "$work" || exit 2
build/mech sweep mechanisms/conveyor.yaml --vary l1=50mm:64mm:100 --vary l2=420mm:440mm:20 \
    --metric range:E.x -q -o "$tmp/ref.csv" || fail "the unsharded sweep"
recipe slurm-sweep.sbatch >sweep.sbatch
recipe slurm-sweep >"$tmp/sweep.sh"
[ -s sweep.sbatch ] && [ -s "$tmp/sweep.sh" ] && pass || fail "no Slurm sweep recipe in docs/batch.md"
sh "$tmp/sweep.sh" >"$tmp/out" 2>"$tmp/err" &
pid=$!
cancel_when_running out/sweep.3.csv.partial mech-sweep 3
wait $pid
merge_refused $? 3/8 out/sweep.csv
recipe slurm-sweep-repair >"$tmp/repair.sh"
if run "the repair recipe (sbatch --array=3)" 0 sh "$tmp/repair.sh"; then
    cmp -s out/sweep.csv "$tmp/ref.csv" && pass || fail "the repaired merge differs from the unsharded run"
fi
# each task used one worker: Slurm's allocation, through the affinity mask
# (nothing said but the sweep's closing count of variants and analyses)
said=$(grep -v "^mech sweep: [0-9]* variants solved through the sweep's one analysis" out/sweep.0.log 2>/dev/null)
[ -n "$said" ] && fail "task 0 said: $(echo "$said" | head -n 2)" || pass

# ---- the batch array, task 1 cancelled, repaired ------------------------------
# (mechanisms/ here: the repository's files and 300 conveyor copies, so that
# a task is still running when it is cancelled)
rm mechanisms  # the link to the repository's directory, not the files
mkdir mechanisms
cp "$repo"/mechanisms/*.yaml mechanisms/
for i in $(seq 100 399); do cp "$repo/mechanisms/conveyor.yaml" "mechanisms/c$i.yaml"; done
recipe slurm-batch.sbatch >batch.sbatch
recipe slurm-batch >"$tmp/batch.sh"
[ -s batch.sbatch ] && [ -s "$tmp/batch.sh" ] && pass || fail "no Slurm batch recipe in docs/batch.md"
sh "$tmp/batch.sh" >"$tmp/out" 2>"$tmp/err" &
pid=$!
cancel_when_running out/summary.1.txt.partial mech-batch 1
wait $pid
merge_refused $? 1/4 out/summary.txt
recipe slurm-batch-repair >"$tmp/brepair.sh"
if run "the batch repair recipe (sbatch --array=1)" 0 sh "$tmp/brepair.sh"; then
    build/mech batch -q --files-from out/files.txt >"$tmp/one.txt" 2>/dev/null
    # file and status (a row kept by --skip-existing has no steps nor times)
    [ "$(awk '{ print $1, $2 }' out/summary.txt | sed 's/ kept$/ ok/')" = "$(awk '{ print $1, $2 }' "$tmp/one.txt")" ] && pass ||
        fail "the repaired batch table differs from one batch's"
    [ "$(ls out/csv/*.csv | wc -l)" -eq "$(wc -l <out/files.txt)" ] && pass ||
        fail "the repaired batch: $(ls out/csv/*.csv | wc -l) CSVs for $(wc -l <out/files.txt) files"
    # each shard wrote its table whole with -o (rows first to TABLE.partial)
    [ "$(ls out/summary.*.txt | wc -l)" -eq 4 ] && [ -z "$(ls out/summary.*.partial 2>/dev/null)" ] && pass ||
        fail "the batch recipe: tables $(ls out/summary.* | tr '\n' ' ')"
fi
cd "$repo" || exit 2
summary
