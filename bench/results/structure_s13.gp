# Stress solve per frame under fire (welded brick block, one brick shattered a frame, thread CPU), before
# (39fe1c9) and after the local balance, reachability kept up to date and the residual routed down (ec8f40b):
# gnuplot -e "data='structure_s13.csv'" structure_s13.gp  (reads the round-1, 20-frame rows)
if (!exists("data")) data = 'structure_s13.csv'
set datafile separator ','
set terminal pngcairo size 900,520
set output 'structure_s13.png'
set logscale xy
set key top left
set xlabel 'bonds'
set ylabel 'solve ms per frame (thread CPU)'
set title 'Converged stress solve under fire, before / after (quiet machine: other processes 0.01 cores)'
sel(b, s, col) = (strcol(1) eq b && strcol(2) eq '1' && strcol(5) eq s && strcol(6) eq '20') ? column(col) : NaN
plot data using 3:(sel('39fe1c9','gauss-seidel',8)) with linespoints lw 2 lc rgb '#c03030' title 'Gauss-Seidel before, p50', \
     data using 3:(sel('39fe1c9','gauss-seidel',9)) with linespoints dt 2 lc rgb '#c03030' title 'Gauss-Seidel before, p99', \
     data using 3:(sel('ec8f40b','gauss-seidel',8)) with linespoints lw 2 lc rgb '#2060c0' title 'Gauss-Seidel after, p50', \
     data using 3:(sel('ec8f40b','gauss-seidel',9)) with linespoints dt 2 lc rgb '#2060c0' title 'Gauss-Seidel after, p99', \
     data using 3:(sel('39fe1c9','conjugate-gradient',8)) with linespoints lw 1 lc rgb '#e09030' title 'CG before, p50', \
     data using 3:(sel('ec8f40b','conjugate-gradient',8)) with linespoints lw 1 lc rgb '#30a060' title 'CG after, p50', \
     data using 3:(sel('ec8f40b','sweeps-12',8)) with linespoints lw 1 lc rgb '#808080' title '12 sweeps (unconverged), p50', \
     1 with lines dt 3 lc rgb 'black' title '1 ms', 2 with lines dt 3 lc rgb '#404040' title '2 ms'
