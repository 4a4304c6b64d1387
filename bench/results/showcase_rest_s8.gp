# Redraws showcase_rest_s8.png from showcase_rest_s8.csv (per-second counts of traced 15 s showcase runs):
#   cd bench/results && gnuplot showcase_rest_s8.gp
if (!exists("csv")) csv = 'showcase_rest_s8.csv'
if (!exists("png")) png = 'showcase_rest_s8.png'
set terminal pngcairo size 1100,560 noenhanced
set output png
set datafile separator ','
set multiplot layout 1,2 title "rubble-demo --showcase --demolish 0.5 --autopilot 15 (demolition_block.cfg): per second"
set key top left
set grid
set xlabel 'game seconds'
set yrange [0:*]
f(c) = (strcol(1) eq c)
set ylabel 'awake debris (light included)'
plot for [c in "before_632ff05 static_targets_only rest_fix rest_fix+demand+above+moved0.5"] \
     csv every ::1 using ($2/60):(f(c) ? $4 : NaN) with linespoints pt 7 title c
set ylabel 'frozen pieces woken in the last second'
plot for [c in "before_632ff05 static_targets_only rest_fix rest_fix+demand+above+moved0.5"] \
     csv every ::1 using ($2/60):(f(c) ? $8 : NaN) with linespoints pt 7 title c
unset multiplot
