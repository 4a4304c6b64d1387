# Redraws scene.png from scene.csv (scripts/scene-bench.sh runs it in the results folder):
#   cd bench/results && gnuplot scene.gp
if (!exists("csv")) csv = 'scene.csv'
if (!exists("png")) png = 'scene.png'
set terminal pngcairo size 1000,560
set output png
set datafile separator ','
set title "rubble-bench scene: 10 shots/s, 60 s, default workers, 60 Hz, idle adoption (Release, 2-core VM)"
set style data histograms
set style histogram clustered gap 1
set style fill solid 0.8 border -1
set ylabel 'ms'
set yrange [0:24]
set grid ytics
set key top left
set xtics rotate by -20 noenhanced
plot csv every ::1 using 8:xtic(stringcolumn(1)) title 'frame p50', \
     '' every ::1 using 9 title 'frame p99', \
     '' every ::1 using 17 title 'impact->adopted p50', \
     '' every ::1 using 18 title 'impact->adopted p99', \
     16.7 with lines dt 2 lw 2 lc rgb 'black' title '16.7 ms'
