# infolerp_pareto saliency --csv saliency.csv: run time against each error, per mesh.
set datafile separator ','
set terminal pngcairo size 1500,520 noenhanced
set output 'saliency.png'
set multiplot layout 1,3
set logscale x
set key top right
set grid
set xlabel 'seconds (compute_saliency, 2 threads, min of 3)'
lbl(c) = strcol(2) eq 'exact' ? (strcol(3) eq '' ? 'exact' : 'exact, eps x1.001') : (strcol(2) eq 'default' ? '' : sprintf('c=%s', strcol(3)))
set ylabel 'relative L2 to exact'
plot for [m in 'bunny00 bunny00_x4 bunny00_x16'] 'saliency.csv' using (strcol(1) eq m ? $5 : 1/0):6 with points pt 7 title m, \
     '' using 5:6:(lbl(0)) with labels font ',7' offset 0,0.7 notitle
set ylabel 'top-10% overlap with exact (goal >= 0.9)'
set yrange [0.8:1.01]
plot for [m in 'bunny00 bunny00_x4 bunny00_x16'] 'saliency.csv' using (strcol(1) eq m ? $5 : 1/0):7 with points pt 7 title m, \
     '' using 5:7:(lbl(0)) with labels font ',7' offset 0,0.7 notitle, 0.9 with lines dt 2 lc rgb 'gray' notitle
set ylabel 'LOD 5% salient distance / exact (goal <= 1.02)'
set yrange [*:*]
plot for [m in 'bunny00 bunny00_x4 bunny00_x16'] 'saliency.csv' using (strcol(1) eq m ? $5 : 1/0):8 with points pt 7 title m, \
     '' using 5:8:(lbl(0)) with labels font ',7' offset 0,0.7 notitle, 1.02 with lines dt 2 lc rgb 'gray' notitle
unset multiplot
