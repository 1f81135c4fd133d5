set terminal pngcairo size 1000,800 noenhanced
set output 'upsample_path_1025.png'
set datafile separator ','
set multiplot layout 2,1 title 'Demo scene 1025x1025 along a camera path (standing still in frames 50-69)'
set xlabel 'frame'
set ylabel 'seconds (log)'
set logscale y
set grid
set key outside right
plot 'upsample_path_1025.csv' using 1:(stringcolumn(2) eq 'per_pixel' ? $3 : 1/0) with points pt 7 ps 0.4 title 'per_pixel', '' using 1:(stringcolumn(2) eq 'ibuffer' ? $3 : 1/0) with points pt 7 ps 0.4 title 'ibuffer', '' using 1:(stringcolumn(2) eq 'ibuffer_reuse' ? $3 : 1/0) with points pt 7 ps 0.4 title 'ibuffer_reuse'
unset logscale y
set ylabel 'PSNR dB vs per_pixel'
plot 'upsample_path_1025.csv' using 1:(stringcolumn(2) eq 'ibuffer' ? $4 : 1/0) with points pt 7 ps 0.4 title 'ibuffer', '' using 1:(stringcolumn(2) eq 'ibuffer_reuse' ? $4 : 1/0) with points pt 7 ps 0.4 title 'ibuffer_reuse', 40 with lines dt 2 title '40 dB'
unset multiplot
