# Redraws demolition.png from demolition_frames.csv (scripts/scene-bench.sh runs it in the results folder):
#   cd bench/results && gnuplot demolition.gp
if (!exists("csv")) csv = 'demolition_frames.csv'
if (!exists("png")) png = 'demolition.png'
if (!exists("build")) build = 'Release'
set terminal pngcairo size 1100,700
set output png
set datafile separator ','
set multiplot layout 2,1 title "rubble-bench scene --pattern shatter, 10 shots/s (stretch: 25), 60 Hz (".build.", 2-core VM): per half second"
set key top left
set grid
set xlabel 's'
set ylabel 'pieces'
plot csv every ::1 using (strcol(1) eq 'assets/scenes/demolition.cfg' ? $2 : NaN):6 with lines lw 2 title '100k: alive', \
     '' every ::1 using (strcol(1) eq 'assets/scenes/demolition.cfg' ? $2 : NaN):7 with lines dt 2 title '100k: awake', \
     '' every ::1 using (strcol(1) eq 'assets/scenes/demolition_block.cfg' ? $2 : NaN):6 with lines lw 2 title '500k: alive', \
     '' every ::1 using (strcol(1) eq 'assets/scenes/demolition_block.cfg' ? $2 : NaN):7 with lines dt 2 title '500k: awake', \
     '' every ::1 using (strcol(1) eq 'assets/scenes/demolition_block.cfg (stretch)' ? $2 : NaN):6 with lines lw 2 title '500k stretch (25 shots/s, 32 cells, 30 Hz budgets): alive', \
     '' every ::1 using (strcol(1) eq 'assets/scenes/demolition.cfg (structure)' ? $2 : NaN):6 with lines lw 1 title '100k with the stress solver: alive'
set ylabel 'ms'
plot csv every ::1 using (strcol(1) eq 'assets/scenes/demolition.cfg' ? $2 : NaN):3 with lines lw 2 title '100k: worst frame', \
     '' every ::1 using (strcol(1) eq 'assets/scenes/demolition.cfg' ? $2 : NaN):5 with lines dt 2 title '100k: worst physics step', \
     '' every ::1 using (strcol(1) eq 'assets/scenes/demolition_block.cfg' ? $2 : NaN):3 with lines lw 2 title '500k: worst frame', \
     '' every ::1 using (strcol(1) eq 'assets/scenes/demolition_block.cfg' ? $2 : NaN):5 with lines dt 2 title '500k: worst physics step', \
     '' every ::1 using (strcol(1) eq 'assets/scenes/demolition_block.cfg (stretch)' ? $2 : NaN):3 with lines lw 1 title '500k stretch: worst frame', \
     '' every ::1 using (strcol(1) eq 'assets/scenes/demolition.cfg (structure)' ? $2 : NaN):3 with lines lw 1 title '100k with the stress solver: worst frame', \
     16.7 with lines dt 3 lc rgb 'black' title '16.7 ms', \
     33.3 with lines dt 3 lc rgb 'gray' title '33 ms'
unset multiplot
