set terminal pngcairo size 1000,1400 noenhanced
set output 'benchmarks/results/path/upsample_path_320.png'
set datafile separator ','
set multiplot layout 4,1 title 'Demo scene 320x240 along two camera paths (orbit: standing still in frames 50-69)'
set xlabel 'frame'
set grid
set key outside right
set ylabel 'orbit: seconds (log)'
set logscale y
plot 'benchmarks/results/path/upsample_path_320.csv' using 2:(stringcolumn(1) eq 'orbit' && stringcolumn(3) eq 'per_pixel' ? $4 : 1/0) with points pt 7 ps 0.4 title 'per_pixel', '' using 2:(stringcolumn(1) eq 'orbit' && stringcolumn(3) eq 'per_pixel_packets' ? $4 : 1/0) with points pt 7 ps 0.4 title 'per_pixel_packets', '' using 2:(stringcolumn(1) eq 'orbit' && stringcolumn(3) eq 'ibuffer' ? $4 : 1/0) with points pt 7 ps 0.4 title 'ibuffer', '' using 2:(stringcolumn(1) eq 'orbit' && stringcolumn(3) eq 'ibuffer_reuse' ? $4 : 1/0) with points pt 7 ps 0.4 title 'ibuffer_reuse', '' using 2:(stringcolumn(1) eq 'orbit' && stringcolumn(3) eq 'ibuffer_reuse_terms' ? $4 : 1/0) with points pt 7 ps 0.4 title 'ibuffer_reuse_terms'
unset logscale y
set ylabel 'orbit: PSNR dB vs per_pixel'
plot 'benchmarks/results/path/upsample_path_320.csv' using 2:(stringcolumn(1) eq 'orbit' && stringcolumn(3) eq 'ibuffer' ? $5 : 1/0) with points pt 7 ps 0.4 title 'ibuffer', '' using 2:(stringcolumn(1) eq 'orbit' && stringcolumn(3) eq 'ibuffer_reuse' ? $5 : 1/0) with points pt 7 ps 0.4 title 'ibuffer_reuse', '' using 2:(stringcolumn(1) eq 'orbit' && stringcolumn(3) eq 'ibuffer_reuse_terms' ? $5 : 1/0) with points pt 7 ps 0.4 title 'ibuffer_reuse_terms', 40 with lines dt 2 title '40 dB'
set ylabel 'walk: seconds (log)'
set logscale y
plot 'benchmarks/results/path/upsample_path_320.csv' using 2:(stringcolumn(1) eq 'walk' && stringcolumn(3) eq 'per_pixel' ? $4 : 1/0) with points pt 7 ps 0.4 title 'per_pixel', '' using 2:(stringcolumn(1) eq 'walk' && stringcolumn(3) eq 'per_pixel_packets' ? $4 : 1/0) with points pt 7 ps 0.4 title 'per_pixel_packets', '' using 2:(stringcolumn(1) eq 'walk' && stringcolumn(3) eq 'ibuffer' ? $4 : 1/0) with points pt 7 ps 0.4 title 'ibuffer', '' using 2:(stringcolumn(1) eq 'walk' && stringcolumn(3) eq 'ibuffer_reuse' ? $4 : 1/0) with points pt 7 ps 0.4 title 'ibuffer_reuse', '' using 2:(stringcolumn(1) eq 'walk' && stringcolumn(3) eq 'ibuffer_reuse_terms' ? $4 : 1/0) with points pt 7 ps 0.4 title 'ibuffer_reuse_terms'
unset logscale y
set ylabel 'walk: PSNR dB vs per_pixel'
plot 'benchmarks/results/path/upsample_path_320.csv' using 2:(stringcolumn(1) eq 'walk' && stringcolumn(3) eq 'ibuffer' ? $5 : 1/0) with points pt 7 ps 0.4 title 'ibuffer', '' using 2:(stringcolumn(1) eq 'walk' && stringcolumn(3) eq 'ibuffer_reuse' ? $5 : 1/0) with points pt 7 ps 0.4 title 'ibuffer_reuse', '' using 2:(stringcolumn(1) eq 'walk' && stringcolumn(3) eq 'ibuffer_reuse_terms' ? $5 : 1/0) with points pt 7 ps 0.4 title 'ibuffer_reuse_terms', 40 with lines dt 2 title '40 dB'
unset multiplot
