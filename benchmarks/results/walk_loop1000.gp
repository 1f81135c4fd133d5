set terminal pngcairo noenhanced size 900,1150
set output 'benchmarks/results/walk_loop1000.png'
set datafile separator ','
set multiplot layout 3,1
set grid
set key bottom right
set xlabel 'frame'
set ylabel 'PSNR (dB)'
set title 'walkthrough 320x240: street -> temple -> street'
plot for [m in 'nld_os_cached nld_os_restart rnd_cached'] 'benchmarks/results/walk_loop1000.csv' using (strcol(1) eq m ? $2 : 1/0):4 with lines title m
set logscale y
set ylabel 'new samples'
set title ''
set key top right
plot for [m in 'nld_os_cached nld_os_restart rnd_cached'] 'benchmarks/results/walk_loop1000.csv' using (strcol(1) eq m ? $2 : 1/0):($3 > 0 ? $3 : 0.5) with lines title m
set ylabel 'seconds per frame'
plot for [m in 'nld_os_cached nld_os_restart rnd_cached'] 'benchmarks/results/walk_loop1000.csv' using (strcol(1) eq m ? $2 : 1/0):5 with lines title m.' agent', 'benchmarks/results/walk_loop1000.csv' using (strcol(1) eq 'nld_os_cached' ? $2 : 1/0):7 with lines dt 2 title 'primary rays alone'
unset multiplot
