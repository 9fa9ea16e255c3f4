# SPDX-License-Identifier: MIT
# Columns are UR's "Gnuplot col." numbers: 1 time, 32-37 q actual,
# 44-49 I actual, 56-58 TCP position (tool vector actual x, y, z).
set terminal pngcairo size 1000,900 font ",10"
set output 'sim-capture.png'
set multiplot layout 3,1 title "urrt-sim --version 5.10 --seed 1: 10 s at 500 Hz, recorded with urrt-dump -F gnuplot"
set grid
set lmargin at screen 0.08
set rmargin at screen 0.85
set key outside right
set xlabel 'controller time [s]'
set ylabel 'joint position [rad]'
plot for [j=0:5] 'capture.dat' using 1:32+j with lines title sprintf('q actual %d', j+1)
set ylabel 'joint current [A]'
plot for [j=0:5] 'capture.dat' using 1:44+j with lines title sprintf('I actual %d', j+1)
set ylabel 'TCP position [m]'
plot for [k=0:2] 'capture.dat' using 1:56+k with lines title 'TCP '.word('x y z', k+1)
unset multiplot
