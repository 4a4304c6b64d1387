# Draws showcase_light.png from showcase_light.csv (rows from report.json and frames.csv of
# `rubble-demo --scene assets/scenes/demolition_block.cfg --showcase --demolish 0.5 --autopilot 30 --headless
# --width 640 --height 360 [--light-per-awake 0]`): cd bench/results && gnuplot showcase_light.gp
set terminal pngcairo size 900,500
set output 'showcase_light.png'
set datafile separator ','
set title "showcase (demolition_block.cfg, --demolish 0.5, 30 s): pieces at the end" noenhanced
set style data histogram
set style histogram rowstacked
set style fill solid 0.8
set boxwidth 0.6
set key top left
set grid y
set ylabel 'pieces'
set yrange [0:3500]
set arrow from graph 0, first 3000 to graph 1, first 3000 nohead dt 3 lc rgb 'black'
plot 'showcase_light.csv' every ::1 using 8:xtic(1) title 'frozen', '' every ::1 using ($6-$7) title 'awake', \
     '' every ::1 using 7 title 'light'
