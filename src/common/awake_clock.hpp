// The time this process has been able to run (internal header): the monotonic clock less the
// time the whole process was stopped or not scheduled at all, as when a job is suspended
// (Slurm's suspend and gang scheduling send SIGSTOP to all of its processes, SIGCONT later).
// Deadlines on other processes count this time, so a job suspended and resumed does not take
// its own ranks or TetGen processes for dead, while a rank stopped alone still is. Durations
// that are reported count wall time (now_seconds).
#pragma once

namespace partet {

// Seconds since an arbitrary start, less every pause seen so far: a gap of more than
// kLongestUnseenPause between two looks of a thread that looks every few milliseconds counts,
// all but that much.
double awake_seconds();

inline constexpr double kLongestUnseenPause = 1.0;

}  // namespace partet
