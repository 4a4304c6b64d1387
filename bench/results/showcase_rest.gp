# Redraws showcase_rest.png from showcase_rest.csv (the governor's per-second counts in the showcase, before
# and after the pile comes to rest): cd bench/results && gnuplot showcase_rest.gp
if (!exists("csv")) csv = 'showcase_rest.csv'
if (!exists("png")) png = 'showcase_rest.png'
set terminal pngcairo size 1100,600 noenhanced
set output png
set datafile separator ','
set multiplot layout 1,2 title "demolition_block.cfg with a charge every 0.5 s: the demo's showcase and rubble-bench scene --demolish"
set key top right
set grid
set xlabel 'game seconds'
set ylabel 'awake debris'
set yrange [0:*]
f(r, c) = (strcol(2) eq r && strcol(3) eq c)
plot csv every ::1 using ($4/60):(f('demo_showcase','before') ? $5 : NaN) with linespoints pt 7 title 'demo, before', \
     '' every ::1 using ($4/60):(f('demo_showcase','after_rest_fix') ? $5 : NaN) with linespoints pt 5 title 'demo, after', \
     '' every ::1 using ($4/60):(f('bench_demolish','before') ? $5 : NaN) with lines lw 2 title 'bench, before', \
     '' every ::1 using ($4/60):(f('bench_demolish','after_rest_fix') ? $5 : NaN) with lines lw 2 title 'bench, after'
set ylabel 'frozen pieces woken per second'
plot csv every ::1 using ($4/60):(f('demo_showcase','before') ? $8+$9 : NaN) with linespoints pt 7 title 'demo, before', \
     '' every ::1 using ($4/60):(f('demo_showcase','after_rest_fix') ? $8+$9 : NaN) with linespoints pt 5 title 'demo, after', \
     '' every ::1 using ($4/60):(f('bench_demolish','before') ? $8+$9 : NaN) with lines lw 2 title 'bench, before', \
     '' every ::1 using ($4/60):(f('bench_demolish','after_rest_fix') ? $8+$9 : NaN) with lines lw 2 title 'bench, after'
unset multiplot
