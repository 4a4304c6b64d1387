# Redraws render.png from render.csv (scripts/render-bench.sh runs it in the results folder):
#   cd bench/results && gnuplot render.gp
if (!exists("csv")) csv = 'render.csv'
if (!exists("png")) png = 'render.png'
# the autopilot runs only: rows of rubble-bench render (a pieces count in column 21) are drawn in render_pieces.png
runs = '< awk -F, ''NR == 1 || $21 == ""'' '.csv
set terminal pngcairo size 1200,560
set output png
set datafile separator ','
set multiplot layout 1,2 title "rubble-demo --autopilot on the thesis's performance\\_test.cfg, 1920x1080 Xvfb window, llvmpipe (2-core VM, shared)"
set style data histograms
set style histogram clustered gap 1
set style fill solid 0.8 border -1
set grid ytics
set key top left
set xtics rotate by -25 noenhanced
set title 'frame rate (wall clock; low when other\_cpu\_cores is high)'
set ylabel 'fps'
plot runs every ::1 using 12:xtic(stringcolumn(2)) title 'fps p50', \
     '' every ::1 using 13 title 'fps p99', \
     55 with lines dt 2 lw 2 lc rgb 'black' title '55 fps target', \
     18 with lines dt 3 lw 2 lc rgb 'red' title '18 fps p99 target'
set y2tics
set y2range [0:2]
set title 'CPU per frame (demo incl. llvmpipe threads, and Xvfb): load independent'
set ylabel 'CPU ms per frame'
plot runs every ::1 using 16:xtic(stringcolumn(2)) title 'demo', \
     '' every ::1 using 17 title 'Xvfb', \
     '' every ::1 using 19 with points pt 7 ps 1.5 axes x1y2 title 'other\_cpu\_cores (right)'
unset multiplot
