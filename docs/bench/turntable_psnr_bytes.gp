# Made by calf-bench; run from this directory: gnuplot turntable_psnr_bytes.gp
set terminal pngcairo size 800,500
set output 'turntable_psnr_bytes.png'
set title "turntable: mean PSNR vs clip bytes (Pareto front: line and circles)"
set xlabel "clip bytes (MB)"
set ylabel "mean PSNR vs ground truth (dB)"
set grid
set offsets graph 0.04, graph 0.12, graph 0.06, graph 0.06
set key outside right top
plot 'turntable_front_bytes.dat' using 1:2 with linespoints lw 2 lc rgb '#999999' pt 6 ps 2.4 title 'Pareto front', \
     'turntable.dat' index 0 using 1:3 with points pt 5 ps 1.6 lc rgb '#000000' title 'base', \
     'turntable.dat' index 1 using 1:3 with points pt 2 ps 1.3 lc rgb '#1f77b4' title 'q', \
     'turntable.dat' index 2 using 1:3 with points pt 3 ps 1.3 lc rgb '#ff7f0e' title 'cell', \
     'turntable.dat' index 3 using 1:3 with points pt 4 ps 1.3 lc rgb '#2ca02c' title 'window', \
     'turntable.dat' index 4 using 1:3 with points pt 6 ps 1.3 lc rgb '#d62728' title 'aabbs', \
     'turntable.dat' index 5 using 1:3 with points pt 8 ps 1.3 lc rgb '#9467bd' title 'depth', \
     'turntable.dat' index 6 using 1:3 with points pt 7 ps 1.3 lc rgb '#8c564b' title 'colour', \
     'turntable.dat' index 7 using 1:3 with points pt 10 ps 1.3 lc rgb '#e377c2' title 'super', \
     'turntable.dat' index 8 using 1:3 with points pt 9 ps 1.3 lc rgb '#17becf' title 'views', \
     'turntable.dat' index 9 using 1:3 with points pt 11 ps 1.3 lc rgb '#7f7f00' title 'steps', \
     'turntable.dat' using 1:3:4 with labels left offset char 0.5,0.4 font ',7' notitle
