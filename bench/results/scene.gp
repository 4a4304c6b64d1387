set terminal pngcairo size 1000,560
# gnuplot bench/results/scene.gp (from the repository root) redraws scene.png from scene.csv
set output 'bench/results/scene.png'
set datafile separator ','
set title "rubble-bench scene: 10 shots/s, 60 s, 1 worker, 60 Hz, idle adoption (Release, 2-core VM, load 1.5-3)"
set style data histograms
set style histogram clustered gap 1
set style fill solid 0.8 border -1
set ylabel 'ms'
set yrange [0:*]
set grid ytics
set key top left
set xtics rotate by -20 noenhanced
f(s) = strstrt(s, '/work/shared/seed/media/') == 1 ? 'seed: '.s[25:] : s[15:]
plot 'bench/results/scene.csv' every ::1 using 8:xtic(f(stringcolumn(1))) title 'frame p50', \
     '' every ::1 using 9 title 'frame p99', \
     '' every ::1 using 17 title 'impact->adopted p50', \
     '' every ::1 using 18 title 'impact->adopted p99', \
     16.7 with lines dt 2 lw 2 lc rgb 'black' title '16.7 ms'
