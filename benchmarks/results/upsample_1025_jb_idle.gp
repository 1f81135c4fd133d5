set terminal pngcairo size 1000,650 noenhanced
set output 'benchmarks/results/upsample_1025_jb_idle.png'
set title 'Demo scene 1025x1025: PSNR against render time (exact methods drawn at 60 dB)'
set xlabel 'CPU seconds, all threads (log)'
set ylabel 'PSNR dB vs full per-pixel evaluation'
set logscale x
set grid
set key bottom right
plot 'benchmarks/results/upsample_1025_jb_idle.dat' index 0 using 1:2 with points pt 4 title 'full_single', 'benchmarks/results/upsample_1025_jb_idle.dat' index 1 using 1:2 with points pt 5 title 'full_packets16', 'benchmarks/results/upsample_1025_jb_idle.dat' index 2 using 1:2 with points pt 6 title 'lowres_bilinear', 'benchmarks/results/upsample_1025_jb_idle.dat' index 3 using 1:2 with points pt 7 title 'joint_bilateral', 'benchmarks/results/upsample_1025_jb_idle.dat' index 4 using 1:2 with points pt 8 title 'contrast', 'benchmarks/results/upsample_1025_jb_idle.dat' index 5 using 1:2 with points pt 9 title 'ibuffer', 'benchmarks/results/upsample_1025_jb_idle.dat' index 6 using 1:2 with points pt 10 title 'ibuffer_linear', 'benchmarks/results/upsample_1025_jb_idle.dat' index 7 using 1:2 with points pt 11 title 'ibuffer_probe', 'benchmarks/results/upsample_1025_jb_idle.dat' index 8 using 1:2 with points pt 12 title 'ibuffer_occl'
