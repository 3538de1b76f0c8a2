# Made by calf-bench; run from this directory: gnuplot mirror-box_psnr_ms.gp
set terminal pngcairo size 800,500
set output 'mirror-box_psnr_ms.png'
set title "mirror-box: mean PSNR vs frame CPU time (Pareto front: line and circles)"
set xlabel "CPU ms per frame: decode + upload + render (median)"
set ylabel "mean PSNR vs ground truth (dB)"
set grid
set offsets graph 0.04, graph 0.12, graph 0.06, graph 0.06
set key outside right top
plot 'mirror-box_front_ms.dat' using 1:2 with linespoints lw 2 lc rgb '#999999' pt 6 ps 2.4 title 'Pareto front', \
     'mirror-box.dat' index 0 using 2:3 with points pt 5 ps 1.6 lc rgb '#000000' title 'base', \
     'mirror-box.dat' index 1 using 2:3 with points pt 2 ps 1.3 lc rgb '#1f77b4' title 'q', \
     'mirror-box.dat' index 2 using 2:3 with points pt 3 ps 1.3 lc rgb '#ff7f0e' title 'cell', \
     'mirror-box.dat' index 3 using 2:3 with points pt 4 ps 1.3 lc rgb '#2ca02c' title 'window', \
     'mirror-box.dat' index 4 using 2:3 with points pt 6 ps 1.3 lc rgb '#d62728' title 'aabbs', \
     'mirror-box.dat' index 5 using 2:3 with points pt 8 ps 1.3 lc rgb '#9467bd' title 'depth', \
     'mirror-box.dat' index 6 using 2:3 with points pt 7 ps 1.3 lc rgb '#8c564b' title 'colour', \
     'mirror-box.dat' index 7 using 2:3 with points pt 10 ps 1.3 lc rgb '#e377c2' title 'super', \
     'mirror-box.dat' index 8 using 2:3 with points pt 9 ps 1.3 lc rgb '#17becf' title 'views', \
     'mirror-box.dat' index 9 using 2:3 with points pt 11 ps 1.3 lc rgb '#7f7f00' title 'steps', \
     'mirror-box.dat' using 2:3:4 with labels left offset char 0.5,0.4 font ',7' notitle
