# gnuplot bench/results/structure_s9.gp (from bench/results; data from structure_demolition_s9.csv and structure_demolition_s9_trace.csv)
set terminal pngcairo size 1100,520
set output 'structure_s9.png'
set multiplot layout 1,2 title "Direct solve on demolition.cfg under fire, main 5c7220b against this branch, alternating (1.0-1.4 other cores)"
set style data histograms
set style histogram clustered gap 1
set style fill solid 0.8 border -1
set grid ytics
set key top left
set yrange [0:*]
set title "structure stage, thread CPU a frame, p99"
set yrange [0:5]
set ylabel 'ms'
$P99 << EOD
"pair 1" 3.49 2.82
"pair 2" 3.33 2.67
"pair 3" 3.85 2.90
EOD
plot $P99 u 2:xtic(1) t 'main', '' u 3 t 'branch', 2 w l lw 2 dt 2 lc rgb 'black' t 'target 2 ms'
set key top right
set title "solves over a CPU threshold (trace, 1,179 solves)"
set yrange [0:*]
set ylabel 'solves'
$OVER << EOD
"> 1.5 ms" 211 101 95
"> 2 ms" 141 35 35
"> 3 ms" 26 8 10
EOD
plot $OVER u 2:xtic(1) t 'main', '' u 3 t 'branch (run 1)', '' u 4 t 'branch (run 2)', 12 w l lw 2 dt 2 lc rgb 'black' t 'p99 rank (12)'
unset multiplot
