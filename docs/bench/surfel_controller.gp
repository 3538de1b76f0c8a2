# The surfel frame-time controller over the factory's 24-pose walk (docs/SURFELS.md).
# Data: tools/surfel_eval.sh writes WORK_DIR/controller.dat (copied here as surfel_controller.dat);
# run from this directory: gnuplot surfel_controller.gp
# Blocks (index): 0, 1 wall-clock runs at 100 ms; 2 the process-CPU-clock run at 120 ms (idle machine).
# Columns: pose, controlled ms, target ms, point size px, mesh triangles, wall ms, CPU ms.
set terminal svg size 900,520 dynamic font 'sans,11'
set output 'surfel_controller.svg'
set multiplot layout 2,1 title "factory walk, 320x240, GL on llvmpipe (2 cores, idle): frame time against the target"
set grid
set key outside right top
set xrange [0.5:23.5]
set xlabel "pose (0: shader compilation, not reported; 1-4: warm-up)"
set ylabel "wall ms"
set object 1 rect from 0.5,90 to 23.5,110 fc rgb '#dddddd' fs solid 0.5 noborder behind
plot 'surfel_controller.dat' index 0 using 1:2 with linespoints pt 7 lc rgb '#1f77b4' title 'wall run 1', \
     'surfel_controller.dat' index 1 using 1:2 with linespoints pt 5 lc rgb '#ff7f0e' title 'wall run 2', \
     100 with lines dt 2 lc rgb '#000000' title 'target +-10 %'
unset object 1
set ylabel "process CPU ms"
set object 2 rect from 0.5,108 to 23.5,132 fc rgb '#dddddd' fs solid 0.5 noborder behind
plot 'surfel_controller.dat' index 2 using 1:2 with linespoints pt 7 lc rgb '#2ca02c' title 'CPU-clock run', \
     120 with lines dt 2 lc rgb '#000000' title 'target +-10 %'
unset multiplot
