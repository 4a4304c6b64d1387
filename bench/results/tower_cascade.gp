# Redraws tower_cascade.png from tower_cascade.csv (written by tests/bullet/TowerCascade_test.cpp with
# RUBBLE_TOWER_CSV=tower_cascade.csv): cd bench/results && gnuplot tower_cascade.gp
if (!exists("csv")) csv = 'tower_cascade.csv'
if (!exists("png")) png = 'tower_cascade.png'
set terminal pngcairo size 900,520 noenhanced
set output png
set datafile separator ','
set datafile missing ''
set title "tower.cfg on Bullet: one charge under the ground floor at t = 0, each slab until it breaks"
set xlabel 'seconds after the charge'
set ylabel 'slab centre height (m; ground at -10)'
set y2label 'storeys whole (pillars and slab)'
set ytics nomirror
set y2tics 0, 1, 6
set y2range [0:6.5]
set xrange [0:3.2]
set grid
set key top right
plot for [k=1:6] csv every ::1 using 2:(column(2 + k)) with lines lw 2 title sprintf('slab %d', k), \
     csv every ::1 using 2:9 axes x1y2 with steps lw 1 dt 2 lc rgb 'black' title 'storeys whole'
