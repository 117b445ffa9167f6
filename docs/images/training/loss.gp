# The loss-curve picture of docs/training.md: gnuplot docs/images/training/loss.gp (from the repository root; Debian's gnuplot-nox)
set terminal pngcairo size 900,420 font ",10"
set output 'docs/images/training/loss.png'
set datafile separator ','
set key top right
set logscale y
set xlabel 'step (batch 64)'
set ylabel 'x0 MSE, normalised units'
set title 'Shipped diffusion models (latent 128): training and validation loss, runs/contact_tiny, runs/motion_tiny, runs/motion_ft' noenhanced
set grid
plot 'runs/contact_tiny/loss.csv' every ::1 using 1:3 with lines lw 1 lc rgb '#1f77b4' title 'contact: train', \
     '' every ::1 using 1:($4 > 0 ? $4 : 1/0) with linespoints pt 7 ps 0.6 lw 2 lc rgb '#1f77b4' title 'contact: validation', \
     'runs/motion_tiny/loss.csv' every ::1 using 1:3 with lines lw 1 lc rgb '#d62728' title 'motion: train', \
     '' every ::1 using 1:($4 > 0 ? $4 : 1/0) with linespoints pt 7 ps 0.6 lw 2 lc rgb '#d62728' title 'motion: validation', \
     'runs/motion_ft/loss.csv' every ::1 using ($1+6000):3 with lines lw 1 lc rgb '#ff9896' title 'motion, trained on (2026-12-04): train', \
     '' every ::1 using ($1+6000):($4 > 0 ? $4 : 1/0) with linespoints pt 7 ps 0.6 lw 2 lc rgb '#ff9896' title 'motion, trained on: validation'
