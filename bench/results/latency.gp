# Redraws latency.png from latency.csv (scripts/latency-bench.sh runs it in the results folder):
#   cd bench/results && gnuplot latency.gp
if (!exists("csv")) csv = 'latency.csv'
if (!exists("png")) png = 'latency.png'
set terminal pngcairo size 1600,640
set output png
set datafile separator ','
set multiplot layout 1,2 title "rubble-demo --autopilot --fire-rate 5 --adopt-ready on the thesis's world.cfg, 1280x720 EGL, llvmpipe (2-core VM, shared)"
set style data histograms
set style histogram clustered gap 1
set style fill solid 0.8 border -1
set grid ytics
set key top left
set xtics rotate by -50 noenhanced font ",9"
set title 'fracture latency, impact -> adopted (runs in order)'
set ylabel "ms (log scale)"
set logscale y
plot csv every ::1 using 14:xtic(stringcolumn(2)) title 'p50', \
     '' every ::1 using 15 title 'p99', \
     50 with lines dt 2 lw 2 lc rgb 'black' title '50 ms p99 target'
set y2tics
set y2range [0:2]
unset logscale y
set title 'frame time (wall clock) and the rest of the machine'
set ylabel 'frame ms'
plot csv every ::1 using 9:xtic(stringcolumn(2)) title 'frame p50', \
     '' every ::1 using 10 title 'frame p99', \
     '' every ::1 using 22 with points pt 7 ps 1.5 axes x1y2 title 'other\_cpu\_cores (right)'
unset multiplot
