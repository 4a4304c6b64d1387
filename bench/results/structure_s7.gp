# gnuplot bench/results/structure_s7.gp (from bench/results, data in structure_s7.csv's solve_p50_ms / solve_p99_ms)
set terminal pngcairo size 1000,520
set output 'structure_s7.png'
set title "Direct solve under fire, thread CPU ms a frame: b755d4a against islands + updates (one batch, 1.6-1.9 other cores)"
set style data histograms
set style histogram clustered gap 1
set style fill solid 0.8 border -1
set logscale y
set ylabel 'solve ms a frame'
set grid ytics
set key top left
set xtics font ',9'
$DATA << EOD
0 "4 blocks of 8x8x8 (islands)\n5632 bonds, fracture" 59.6911 22.3007 90.2737 81.9581
1 "1 block of 8x8x8\n1408 bonds, fracture" 16.3178 23.0977 21.6424 32.5073
2 "1 block of 8x8x8\n1408 bonds, break" 15.4346 8.2088 21.9904 24.2984
3 "1 block of 16x26x16\n19136 bonds, break" 954.9755 336.2379 1045.5649 1191.9838
EOD
plot $DATA u 3:xtic(2) t 'p50 b755d4a', '' u 4 t 'p50 islands+updates', '' u 5 t 'p99 b755d4a', '' u 6 t 'p99 islands+updates'
