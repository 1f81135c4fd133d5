set terminal pngcairo noenhanced size 900,800
set output 'benchmarks/results/walk.png'
set datafile separator ','
set multiplot layout 2,1
set grid
set key bottom right
set xlabel 'frame'
set ylabel 'PSNR (dB)'
set title 'walkthrough 320x240: street -> temple -> street'
plot for [m in 'nld_os_cached nld_os_restart rnd_cached'] 'benchmarks/results/walk.csv' using (strcol(1) eq m ? $2 : 1/0):4 with lines title m
set logscale y
set ylabel 'new samples'
set title ''
set key top right
plot for [m in 'nld_os_cached nld_os_restart rnd_cached'] 'benchmarks/results/walk.csv' using (strcol(1) eq m ? $2 : 1/0):($3 > 0 ? $3 : 0.5) with lines title m
unset multiplot
