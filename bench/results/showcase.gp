# Redraws showcase.png from showcase.csv (scripts/showcase-bench.sh runs it in the results folder):
#   cd bench/results && gnuplot showcase.gp
if (!exists("csv")) csv = 'showcase.csv'
if (!exists("png")) png = 'showcase.png'
set terminal pngcairo size 1000,520
set output png
set datafile separator ','
set title "showcase (demolition_block.cfg, --demolish 0.5): pieces at the end; label: end over before frame p50" noenhanced
set style data histogram
set style histogram rowstacked
set style fill solid 0.8
set boxwidth 0.6
set key top left
set grid y
set ylabel 'pieces'
set yrange [0:3500<*]
set arrow from graph 0, first 3000 to graph 1, first 3000 nohead dt 3 lc rgb 'black'
plot csv every ::1 using 11:xtic(sprintf("%s %ss x%s", stringcolumn(2), stringcolumn(4), stringcolumn(16))) title 'frozen', \
     '' every ::1 using ($9-$10) title 'awake', '' every ::1 using 10 title 'light'
