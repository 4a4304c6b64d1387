# Redraws mega_scene.png from mega_scene.csv (scripts/mega-scene-bench.sh runs it):
#   cd bench/results && gnuplot mega_scene.gp
if (!exists("csv")) csv = 'mega_scene.csv'
if (!exists("png")) png = 'mega_scene.png'
set terminal pngcairo size 1200,560
set output png
set datafile separator ','
set title "1M-triangle objects shot 10 times a second (rubble-bench scene, paced at 60 Hz): main-thread frame ms" noenhanced
set style data histogram
set style histogram clustered gap 1
set style fill solid 0.8
set key top left
set grid y
set bmargin 5
set xtics noenhanced
set ylabel 'ms'
set yrange [0:*]
set arrow from graph 0, first 16.7 to graph 1, first 16.7 nohead dt 3 lc rgb 'black'
set label '16.7 ms (60 Hz)' at graph 0.01, first 17.4
plot csv every ::1 using 10:xtic(sprintf("%s\n%s\n%s", stringcolumn(21), stringcolumn(1), stringcolumn(4))) title 'frame p50', \
     '' every ::1 using 11 title 'frame p99', '' every ::1 using 12 title 'frame max', \
     '' every ::1 using 15 title 'idle adoption max'
