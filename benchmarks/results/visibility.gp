set datafile separator ','
set terminal pngcairo size 900,560 noenhanced
set output 'visibility.png'
set xlabel 'seconds (visibility channel, one core)'
set ylabel 'mean JS of p(V|t) against n = 4 (bits)'
set logscale xy
set key outside right
set grid
plot for [m in 'refined_elephant armadillo'] 'visibility.csv' using (strcol(1) eq m ? $4 : 1/0):($6 > 0 ? $6 : 1e-7) with points pt 7 title m, '' using 4:($6 > 0 ? $6 : 1e-7):(sprintf('%s %s', stringcolumn(2), stringcolumn(3))) with labels font ',7' offset 0,0.6 notitle
