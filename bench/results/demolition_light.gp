# Redraws demolition_light.png from demolition_light.csv (scripts/light-bench.sh runs it in the results folder):
#   cd bench/results && gnuplot demolition_light.gp
if (!exists("csv")) csv = 'demolition_light.csv'
if (!exists("png")) png = 'demolition_light.png'
set terminal pngcairo size 1000,600
set output png
set datafile separator ','
set multiplot layout 1,2 title "demolition.cfg, shatter, 10 shots/s, 60 s at 60 Hz: pieces over the awake budget retire or become light"
set key bottom right
set grid
set xlabel 'seed'
set xtics 1
set offsets 0.5, 0.5, 0, 0
set yrange [0:*]
set ylabel 'pieces alive at the end'
plot csv every ::1 using 3:(strcol(1) eq 'retire' ? $10 : NaN) with points pt 7 ps 1.5 title 'retire', \
     '' every ::1 using 3:(strcol(1) eq 'light' ? $10 : NaN) with points pt 5 ps 1.5 title 'light'
set ylabel 'physics step p99 (ms)'
plot csv every ::1 using 3:(strcol(1) eq 'retire' ? $8 : NaN) with points pt 7 ps 1.5 title 'retire', \
     '' every ::1 using 3:(strcol(1) eq 'light' ? $8 : NaN) with points pt 5 ps 1.5 title 'light', \
     8 with lines dt 3 lc rgb 'black' title '8 ms budget'
unset multiplot
