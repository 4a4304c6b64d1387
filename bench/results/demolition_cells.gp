# Redraws demolition_cells.png from demolition_cells.csv: cd bench/results && gnuplot demolition_cells.gp
if (!exists("csv")) csv = 'demolition_cells.csv'
if (!exists("png")) png = 'demolition_cells.png'
set terminal pngcairo size 1000,600 noenhanced
set output png
set datafile separator ','
set multiplot layout 1,2 title "demolition.cfg, 60 s of 10 shatter shots/s at 60 Hz, by shatter cells (one sitting, other cores <= 0.04)"
set grid
set xlabel 'shatter cells'
set xrange [12:36]
set xtics (16, 24, 32)
set yrange [0:10000]
set key top left
set ylabel 'pieces'
plot csv every ::1 using 4:7 with linespoints pt 7 ps 1.5 title 'alive at the end', \
     '' every ::1 using 4:8 with linespoints pt 5 ps 1.5 title 'retired by the awake budget', \
     '' every ::1 using 4:9 with linespoints pt 9 ps 1.5 title 'dust (below 1 litre)', \
     7500 with lines dt 3 lc rgb 'black' title 'target 7,500'
set ylabel 'ms'
set yrange [0:12]
set key bottom right
plot csv every ::1 using 4:16 with linespoints pt 7 ps 1.5 title 'physics step p99', \
     '' every ::1 using 4:14 with linespoints pt 5 ps 1.5 title 'frame p99', \
     8 with lines dt 3 lc rgb 'black' title '8 ms physics budget'
unset multiplot
