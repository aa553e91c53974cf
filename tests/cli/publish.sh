#!/usr/bin/env bash
# The publish as a state machine: a signal at every step of it leaves either the complete previous
# set or the complete new set, never a mix and never nothing, and the message and exit code say
# which (0 and "complete": the new set; 128+signal and "as they were": the previous one). A
# SIGKILL at any step leaves a journal that the next partet command completes. The previous set
# has more .pvtu piece files and MSH partitions than the new one (K=4 then K=2): they belong to
# it and go with it; a single .msh another run wrote under a partition's name stays.
# Also: an interrupt before the publish removes every temporary, however many (K=80 .pvtu); a
# slow publish interrupted for real at random moments; a run waiting for another's lock says so
# and gives up in bounded time.
# Usage: publish.sh PARTET
set -uo pipefail
partet=$(realpath "$1")
source "$(dirname "$0")/../harness.sh"
cd "$work"
# Small, since the publish is run about 130 times; K=80 (section 3) needs a larger one.
"$partet" generate torus --faces 1000 -o torus.off > /dev/null
"$partet" generate torus --faces 3000 -o torus80.off > /dev/null
old=(mesh torus.off -o m -k 4 --format tetgen,pvtu,msh-parts --report m.json --quiet)
new=(mesh torus.off -o m -k 2 --format tetgen,pvtu,msh-parts --report m.json --quiet)

# The two sets, once: the previous one as published, the new one as written under another name.
mkdir old_set new_set
(cd old_set && ln -s ../torus.off . && "$partet" "${old[@]}" && rm torus.off) || bad "previous set"
(cd new_set && ln -s ../torus.off . && "$partet" "${new[@]}" && rm torus.off) || bad "new set"
restore_old() { rm -f m* && cp old_set/* .; }
listing() { ls -1 | grep -v -e '^old_set$' -e '^new_set$' -e '^torus.off$' -e '^torus80.off$' -e '^log$' | sort | tr '\n' ' '; }
# Each set's checksums but the report's, once: a comparison is then one sha256sum, not a cmp per
# file (this test compares about 100 times; a process costs about 10 ms here).
sums_of() { (cd "$1" && sha256sum $(ls | grep -vx m.json)); }
old_sums=$(sums_of old_set) new_sums=$(sums_of new_set)
same_files() {  # DIR SUMS: the files here are exactly DIR's (the report's timings may differ)
  [ "$(listing)" = "$(cd "$1" && ls -1 | sort | tr '\n' ' ')" ] || return 1
  sha256sum --quiet --status -c <<< "$2" || return 1
  # The report: the same text but for its numbers (a python3 check here cost 40 s of this test).
  [ "$(tr -d '0-9.eE+-' < m.json)" = "$(tr -d '0-9.eE+-' < "$1/m.json")" ]
}
is_old() { same_files old_set "$old_sums" && cmp -s m.json old_set/m.json; }
is_new() { same_files new_set "$new_sums" && "$partet" check torus.off m > /dev/null 2>&1; }
# Each loop below spells its outcomes as letters (n: the new set, o: the previous one); a case that
# is neither fails the test and shows as "!".
missed() { bad "$1"; outcomes+="!"; }
# The new run, killed (SIGKILL) at publish step $1; no "Killed" line.
killed_at() { (PARTET_TEST_PUBLISH_SIGNAL="$1:9" "$partet" "${new[@]}" > log 2>&1; true) 2> /dev/null; }

# The publish has 31 steps here: the journal written (0, and 1 past its error handling), 12
# previous files kept aside, 4 previous piece files and partitions the new set does not have, 12
# moves, the cleanup. Step 0 is the moment just after the journal is written: an interrupt that
# removed the temporaries there would leave a journal whose completion removes the previous set's
# extra files, so the previous set would be broken and the new one lost.
steps=30
# 1. SIGTERM at each step and one past the end (nothing happens); SIGINT and SIGHUP at every
#    third.
for sig in TERM INT HUP; do
  num=$(kill -l "$sig")
  outcomes=""
  tried=$(seq 0 $((steps + 1)))
  [ "$sig" = TERM ] || tried=$(seq 0 3 $((steps + 1)))
  for step in $tried; do
    restore_old
    PARTET_TEST_PUBLISH_SIGNAL="$step:$num" "$partet" "${new[@]}" > log 2>&1
    code=$?
    if [ "$code" -eq 0 ] && is_new && { [ "$step" -gt "$steps" ] || grep -q "SIG$sig after the output was published: the new files at m are complete" log; }; then
      outcomes+="n"
    elif [ "$code" -eq $((128 + num)) ] && is_old && grep -q "interrupted (SIG$sig): no output written; the files at m are as they were" log; then
      outcomes+="o"
    else
      missed "SIG$sig at publish step $step: exit $code, files: $(listing), says: $(cat log)"
    fi
  done
  [[ "$outcomes" != *"!"* ]] && ok "SIG$sig at publish steps $(echo $tried | tr ' ' ,): $outcomes (n: new set complete, exit 0; o: previous set, exit $((128 + num)))"
done

# 2. SIGKILL at each step: the journal names every file; `partet check` (or info, or the next
#    mesh) completes the publish, and the set is then the new one, whole.
outcomes=""
for step in $(seq 0 $steps); do
  restore_old
  killed_at "$step"
  case $((step % 3)) in
    0) "$partet" check torus.off m > log 2>&1 ;;
    1) "$partet" info m > log 2>&1 ;;
    2) "$partet" mesh torus.off -o other --quiet > /dev/null 2>&1 && rm -f other.* && "$partet" info m.node > log 2>&1 ;;
  esac
  if is_new && grep -q "completed the publish of 12 file(s)" log; then outcomes+="n"
  else missed "SIGKILL at publish step $step: files after the next command: $(listing); it said: $(cat log)"; fi
done
[[ "$outcomes" != *"!"* ]] && ok "SIGKILL at each of $((steps + 1)) publish steps, then check/info/mesh completes the new set: $outcomes"

# 2b. SIGKILL, then one of the new files still waiting under its temporary name is removed, or
#     replaced by another file (a cleanup script, a sync tool, a user): the journal cannot be
#     completed, and the next command puts the previous set back whole instead (its files the new
#     set superseded included), leaving no temporary, second name or journal.
for action in removed replaced; do
  outcomes=""
  for step in 0 12 24 29; do
    restore_old
    killed_at "$step"
    waiting=$(ls | grep '\.tmp-' | grep -v '\.old\.tmp-' | tail -1)  # a new file, not a previous one's second name
    if [ -n "$waiting" ]; then
      rm "$waiting"
      [ "$action" = replaced ] && echo "not partet's" > "$waiting"
    fi
    "$partet" info m > log 2>&1
    if [ -n "$waiting" ] && is_old && ! ls | grep -q -e '\.tmp-' -e '\.old\.' -e 'partet-publish' &&
      grep -q "could not complete the publish.*was removed or replaced meanwhile; the previous files are back in place" log; then
      outcomes+="o"
    else
      missed "SIGKILL at publish step $step, then '$waiting' $action: files after the next command: $(listing); it said: $(cat log)"
    fi
  done
  [[ "$outcomes" != *"!"* ]] && ok "SIGKILL at publish steps 0,12,24,29, then a waiting new file $action: the previous set back: $outcomes"
done

# 2c. SIGKILL with 6 of 12 new files moved in, then a file put under the temporary name of one
#     that moved: it is not moved over the new file; the new set is completed and that file goes.
restore_old
killed_at 24
suffix=$(ls | grep '\.tmp-' | grep -v '\.old\.tmp-' | head -1 | sed 's/.*\(\.tmp-.*\)/\1/')
moved=$(for f in $(ls new_set); do [ -e "$f$suffix" ] || { [ -e "$f" ] && echo "$f"; }; done | grep -v m.json | head -1)
if [ -n "$suffix" ] && [ -n "$moved" ]; then
  echo "not partet's" > "$moved$suffix"
  "$partet" info m > log 2>&1
  is_new && ! ls | grep -q -e '\.tmp-' -e 'partet-publish' && grep -q "completed the publish of 12 file(s)" log &&
    ok "SIGKILL after 6 moves, then a file under the temporary name of '$moved' (moved in): the new set completed, that file gone" ||
    bad "SIGKILL after 6 moves, then a file under '$moved$suffix': files after the next command: $(listing); it said: $(cat log)"
else
  bad "SIGKILL at publish step 24 left no moved new file to test with (suffix '$suffix', files: $(listing))"
fi

# 2d. A publish killed at another prefix whose file is named like a piece file of this set (-o m_p5
#     --format vtu): a run at m removes dead runs' temporaries of its piece files, but not that
#     one, which the other prefix's journal needs; the next command there completes it.
mkdir other_prefix && cd other_prefix && ln -s ../torus.off .
(PARTET_TEST_PUBLISH_SIGNAL="0:9" "$partet" mesh torus.off -o m_p5 --format vtu --quiet > log 2>&1; true) 2> /dev/null
waiting=$(ls | grep -c 'm_p5\.vtu\.tmp-')
"$partet" mesh torus.off -o m -k 2 --format pvtu --quiet > log 2>&1
code=$?
kept=$(ls | grep -c 'm_p5\.vtu\.tmp-')
"$partet" check torus.off m_p5.vtu > log 2>&1
if [ "$waiting" = 1 ] && [ $code = 0 ] && [ "$kept" = 1 ] && grep -q "completed the publish of 1 file(s)" log &&
  [ -s m_p5.vtu ] && ! ls | grep -q '\.tmp-'; then
  ok "a killed publish at m_p5 (.vtu) beside a .pvtu set at m: its waiting file kept, then completed"
else
  bad "a killed publish at m_p5 beside a .pvtu set at m: waiting $waiting, kept $kept, exit $code: $(ls | tr '\n' ' ') $(cat log)"
fi
cd .. && rm -rf other_prefix

# 3. Interrupted before the publish, with 82 files written (K=80 .pvtu): none is left behind.
restore_old
PARTET_TEST_PAUSE_BEFORE_PUBLISH_MS=15000 "$partet" mesh torus80.off -o m -k 80 --format pvtu --quiet > log 2>&1 &
pid=$!
for i in $(seq 600); do [ "$(ls | grep -c '\.tmp-')" -ge 82 ] && break; sleep 0.1; done
written=$(ls | grep -c '\.tmp-')
kill -TERM "$pid"
wait "$pid"
code=$?
[ "$code" -eq 143 ] && [ "$written" -ge 82 ] && is_old && ! ls | grep -q '\.tmp-' &&
  ok "SIGTERM before publishing $written temporaries: all removed, previous set intact" ||
  bad "SIGTERM before publishing $written temporaries: exit $code, left: $(listing)"

# 4. A slow publish (100 ms a step, as on a slow network filesystem) interrupted for real at
#    random moments.
outcomes=""
for delay in 0.2 0.5 0.9 1.4 2.0 2.7; do
  restore_old
  PARTET_TEST_PUBLISH_DELAY_MS=100 "$partet" "${new[@]}" > log 2>&1 &
  pid=$!
  sleep "$delay"
  kill -INT "$pid" 2> /dev/null
  wait "$pid"
  code=$?
  if [ "$code" -eq 0 ] && is_new; then outcomes+="n"
  elif [ "$code" -eq 130 ] && is_old; then outcomes+="o"
  else missed "SIGINT after $delay s of a slow run: exit $code, files: $(listing), says: $(cat log)"; fi
done
[[ "$outcomes" != *"!"* ]] && ok "SIGINT at 6 moments of a slow run: $outcomes"

# 5. A run that cannot get the lock (the holder is stopped) says what it waits for and gives up
#    in bounded time, leaving the previous files and no temporaries of its own; once the holder
#    goes on, its publish completes.
restore_old
PARTET_TEST_PUBLISH_DELAY_MS=300 "$partet" "${new[@]}" > log.holder 2>&1 &
holder=$!
# Stopped once its journal names it (a moment after the journal file appears: see below).
for i in $(seq 600); do grep -q "^owner $holder " m.partet-publish 2> /dev/null && break; sleep 0.05; done
kill -STOP "$holder"
start=$(date +%s)
PARTET_TEST_PUBLISH_WAIT_S=3 "$partet" mesh torus.off -o m -k 3 --quiet > log 2>&1
code=$?
waited=$(($(date +%s) - start))
grep -q "waiting for another partet run (pid $holder on this host)" log &&
  grep -q "gave up after 3 s waiting for another partet run (pid $holder" log && [ "$code" -eq 1 ] && [ "$waited" -le 20 ] &&
  [ -z "$(ls | grep '\.tmp-' | grep -v "\.tmp-$holder-")" ] &&
  ok "waiting for a stopped run's lock: said so, gave up after $waited s (exit $code)" ||
  bad "lock wait: exit $code after $waited s: $(cat log)"
kill -CONT "$holder"
wait "$holder"
code=$?
[ "$code" -eq 0 ] && rm -f log.holder && is_new && ok "the stopped run, continued, published its set" ||
  bad "the continued run: exit $code, files $(listing)"

# 5b. A holder stopped after taking the journal but before writing it (held here by a process
#     that locks an empty one): the waiting run says it has not named itself, not "pid 0".
restore_old
python3 -c "
import fcntl, sys, time
f = open('m.partet-publish', 'w'); fcntl.lockf(f, fcntl.LOCK_EX); print('held', flush=True); time.sleep(60)
" > held.log &
locker=$!
for i in $(seq 200); do grep -q held held.log 2> /dev/null && break; sleep 0.05; done
PARTET_TEST_PUBLISH_WAIT_S=2 "$partet" mesh torus.off -o m -k 3 --quiet > log 2>&1
code=$?
kill "$locker" 2> /dev/null
wait "$locker" 2> /dev/null
rm -f held.log m.partet-publish
[ "$code" -eq 1 ] && grep -q "gave up after 2 s waiting for another partet run (its journal not yet written)" log &&
  is_old && ok "a lock holder that has not written its journal: said so, gave up (exit $code), previous set kept" ||
  bad "a holder without a journal: exit $code, files $(listing): $(cat log)"

# 6. A single .msh at m_7 (another run's, named like a partition) is not the set's: it stays,
#    while the previous set's partitions 4 and 5 go.
restore_old
"$partet" mesh torus.off -o m_7 --format msh --quiet && cp m_7.msh other.msh
"$partet" "${new[@]}" > log 2>&1
code=$?
[ "$code" -eq 0 ] && cmp -s m_7.msh other.msh && [ ! -e m_4.msh ] && [ ! -e m_5.msh ] && [ -e m_3.msh ] &&
  ok "a single .msh named like a partition stays; the previous set's extra partitions go" ||
  bad "a single .msh named like a partition: exit $code, files: $(listing)"
rm -f m_7.msh other.msh

summary
