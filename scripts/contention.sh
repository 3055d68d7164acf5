# Sourced by paper/build.sh and scripts/ensemble-scaling.sh: how much of the machine other processes
# used while a command of ours ran, for the timing rule of whole-process wall times (paper/timing_rule.py).
#   contention_start; COMMAND; contention_share   -> prints the share of all cores others used (0..1)
# Busy CPU ticks from /proc/stat (user, nice, system, irq, softirq, steal: a host taking a core counts)
# less the CPU ticks of this shell's waited-for children (/proc/$$/stat: cutime + cstime).
busy_ticks() { awk '/^cpu / { print $2 + $3 + $4 + $7 + $8 + $9 }' /proc/stat; }
own_ticks() { awk '{ print $16 + $17 }' "/proc/$$/stat"; }
contention_start() { contention_b0="$(busy_ticks)"; contention_o0="$(own_ticks)"; contention_t0="$(date +%s.%N)"; }
contention_share() {
  awk -v t1="$(date +%s.%N)" -v t0="$contention_t0" -v b1="$(busy_ticks)" -v b0="$contention_b0" \
      -v o1="$(own_ticks)" -v o0="$contention_o0" -v hz="$(getconf CLK_TCK)" -v n="$(nproc)" \
    'BEGIN { o = ((b1 - b0) - (o1 - o0)) / (hz * n * (t1 - t0)); printf "%.4f\n", (o > 0 ? o : 0) }'
}
