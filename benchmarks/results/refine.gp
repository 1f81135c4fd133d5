set terminal pngcairo noenhanced size 900,600
set output 'benchmarks/results/refine.png'
set datafile separator ','
set key bottom right
set logscale x
set xlabel 'shading samples'
set ylabel 'PSNR (dB)'
set title 'NLD refinement criteria: street scene, 320x240'
set grid
plot for [c in 'NLD_OS NLD_IS RND'] 'benchmarks/results/refine.csv' using (strcol(1) eq c ? $3 : 1/0):7 with linespoints title c
