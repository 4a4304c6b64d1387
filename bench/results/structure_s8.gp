# gnuplot bench/results/structure_s8.gp (from bench/results; data from structure_demolition_s8.csv and structure_block_s8.csv)
set terminal pngcairo size 1100,520
set output 'structure_s8.png'
set multiplot layout 1,2 title "Direct solve, 632ff05 against this branch, runs alternating (1.6-1.7 other cores busy)"
set style data histograms
set style histogram clustered gap 1
set style fill solid 0.8 border -1
set grid ytics
set key top left
set logscale y
set title "demolition.cfg under fire, thread CPU a solve"
set ylabel 'ms'
$DEMO << EOD
"p50" 0.621 0.721 0.627 0.824
"p90" 4.793 3.349 4.589 3.979
"p99" 11.14 6.47 11.26 7.55
"max" 90.3 95.3 89.1 101.4
EOD
plot $DEMO u 2:xtic(1) t '632ff05 (run 1)', '' u 3 t 'branch (run 2)', '' u 4 t '632ff05 (run 3)', '' u 5 t 'branch (run 4)'
unset logscale y
set yrange [0:*]
set title "8x8x8 bricks (1,408 bonds), a fracture a frame"
$BLOCK << EOD
"p50 pair 1" 21.808 17.423
"p50 pair 2" 18.748 18.511
"p99 pair 1" 26.387 22.548
"p99 pair 2" 25.149 21.424
EOD
plot $BLOCK u 2:xtic(1) t '632ff05', '' u 3 t 'branch'
unset multiplot
