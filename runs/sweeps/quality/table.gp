# gnuplot script written by bimart sweep: gnuplot table.gp draws table.png
set terminal pngcairo size 1800,1000 font ',10'
set output 'table.png'
set datafile separator '\t'
set datafile missing 'NaN'
set style data histograms
set style histogram clustered gap 1
set style fill solid 0.85 border -1
set key top right
set grid ytics
set xtics rotate by -35 left
set yrange [0:*]
set multiplot layout 2,6 title 'sweep quality: ours (blue) and the paper (grey)'
set title 'Mul cm ↑'
plot 'table.dat' using 2:xtic(1) title 'ours' lc rgb '#3060c0', '' using 3 title 'paper' lc rgb '#a0a0a0'
set title 'Accel ↓'
plot 'table.dat' using 4:xtic(1) title 'ours' lc rgb '#3060c0', '' using 5 title 'paper' lc rgb '#a0a0a0'
set title 'Pen 1cm % ↓'
plot 'table.dat' using 6:xtic(1) title 'ours' lc rgb '#3060c0', '' using 7 title 'paper' lc rgb '#a0a0a0'
set title 'Pen 5mm % ↓'
plot 'table.dat' using 8:xtic(1) title 'ours' lc rgb '#3060c0', '' using 9 title 'paper' lc rgb '#a0a0a0'
set title 'Pen 3mm % ↓'
plot 'table.dat' using 10:xtic(1) title 'ours' lc rgb '#3060c0', '' using 11 title 'paper' lc rgb '#a0a0a0'
set title 'Depth mm ↓'
plot 'table.dat' using 12:xtic(1) title 'ours' lc rgb '#3060c0', '' using 13 title 'paper' lc rgb '#a0a0a0'
set title 'Con % ↑'
plot 'table.dat' using 14:xtic(1) title 'ours' lc rgb '#3060c0', '' using 15 title 'paper' lc rgb '#a0a0a0'
set title 'Art % ↑'
plot 'table.dat' using 16:xtic(1) title 'ours' lc rgb '#3060c0', '' using 17 title 'paper' lc rgb '#a0a0a0'
set title 'CM cm ↓'
plot 'table.dat' using 18:xtic(1) title 'ours' lc rgb '#3060c0', '' using 19 title 'paper' lc rgb '#a0a0a0'
set title 'Implaus % ↓'
plot 'table.dat' using 20:xtic(1) title 'ours' lc rgb '#3060c0', '' using 21 title 'paper' lc rgb '#a0a0a0'
set title 'Cavity % ↓'
plot 'table.dat' using 22:xtic(1) title 'ours' lc rgb '#3060c0', '' using 23 title 'paper' lc rgb '#a0a0a0'
unset multiplot
