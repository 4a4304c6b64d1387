# Draws structure_s5.png from structure_block_s5.csv and structure_demolition_s5.csv (docs/structure.md,
# "Where the direct solve's time goes"):  cd bench/results && gnuplot structure_s5.gp
set terminal pngcairo size 1100,800
set output 'structure_s5.png'
set datafile separator ','
set style data histogram
set style histogram clustered gap 1
set style fill solid 0.8 border -1
set logscale y
set yrange [0.5:*]
set grid ytics
set key top left
set multiplot layout 2,1
set title "brick block under fire (rubble-bench structure): solve a frame, thread CPU ms"
set xtics rotate by -20 font ',9'
plot 'structure_block_s5.csv' every ::1 using 7:xtic(strcol(4).' '.strcol(2).(strcol(4) eq 'direct' ? ' ('.strcol(1).')' : '')) title 'p50', \
     '' every ::1 using 8 title 'p99', 1 with lines dt 2 lc rgb 'black' title '1 ms budget'
set title "demolition.cfg under fire (20 s, 10 shots/s, shatter): structure solve a frame, wall ms (loaded machine)"
plot 'structure_demolition_s5.csv' every ::1::5 using 7:xtic(1) title 'p50', \
     '' every ::1::5 using 8 title 'p99', 1 with lines dt 2 lc rgb 'black' title '1 ms budget'
unset multiplot
