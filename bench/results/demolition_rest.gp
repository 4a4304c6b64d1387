# Redraws demolition_rest.png from demolition_rest.csv (scripts/rest-bench.sh runs it in the results folder):
#   cd bench/results && gnuplot demolition_rest.gp
if (!exists("csv")) csv = 'demolition_rest.csv'
if (!exists("png")) png = 'demolition_rest.png'
set terminal pngcairo size 1000,600 noenhanced
set output png
set datafile separator ','
set multiplot layout 1,2 title "demolition.cfg, shatter, 10 shots/s at 60 Hz: before and after the pile comes to rest, and hulls capped at 16 points"
set key bottom right
set grid
set xlabel 'seed'
set xtics 1
set offsets 0.5, 0.5, 0, 0
set yrange [0:*]
set ylabel 'pieces alive at the end'
plot csv every ::1 using 3:(strcol(2) eq 'before' ? $10 : NaN) with points pt 7 ps 1.5 title 'before', \
     '' every ::1 using 3:(strcol(2) eq 'after' ? $10 : NaN) with points pt 5 ps 1.5 title 'after', \
     '' every ::1 using 3:(strcol(2) eq 'cap16' ? $10 : NaN) with points pt 9 ps 1.5 title 'after, cap 16'
set ylabel 'physics step p99 (ms)'
plot csv every ::1 using 3:(strcol(2) eq 'before' ? $8 : NaN) with points pt 7 ps 1.5 title 'before', \
     '' every ::1 using 3:(strcol(2) eq 'after' ? $8 : NaN) with points pt 5 ps 1.5 title 'after', \
     '' every ::1 using 3:(strcol(2) eq 'cap16' ? $8 : NaN) with points pt 9 ps 1.5 title 'after, cap 16', \
     8 with lines dt 3 lc rgb 'black' title '8 ms budget'
unset multiplot
