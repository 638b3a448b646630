# written by hapticstudy (bench/study/report.cpp): one plot per part of the study
reset
set terminal pngcairo size 1100,660 font 'Sans,10'
set output "docs/accuracy/pairs_8.png"
set lmargin at screen 0.08
set rmargin at screen 0.63
set bmargin at screen 0.1
set tmargin at screen 0.91
set logscale xy
set grid xtics ytics mxtics mytics lc rgb '#dddddd'
set format x '10^{%L}'
set format y '10^{%L}'
set xrange [95.598:1.77828e+06]
set yrange [5.29327e-17:60.3467]
set xlabel 'median time per query (ns)'
set ylabel 'p99 force error (N)'
set title "What accuracy costs in time: pairs/8" noenhanced
set key at screen 0.65, screen 0.91 left top Left reverse font 'Sans,9' spacing 1.2
set arrow from 1e+06, graph 0 to 1e+06, graph 1 nohead dt 3 lw 1.5 lc rgb '#b00000' back
set label "1 kHz tick" at 1e+06, graph 0.97 right rotate by 90 offset -1.3,0 font 'Sans,8' tc rgb '#b00000'
set arrow from 250000, graph 0 to 250000, graph 1 nohead dt 3 lw 1.5 lc rgb '#b00000' back
set label "4 kHz tick" at 250000, graph 0.97 right rotate by 90 offset -1.3,0 font 'Sans,8' tc rgb '#b00000'
set arrow from graph 0, first 1.67388e-16 to graph 1, first 1.67388e-16 nohead dt 2 lc rgb '#999999' back
set label 'no error (exact)' at graph 0.99, first 1.67388e-16 right offset 0,0.7 font 'Sans,8' tc rgb '#666666'
set label "2mm" at graph 0.268689, graph 0.912978 left font 'Sans,8' front noenhanced
set label "1mm" at graph 0.450088, graph 0.912643 left font 'Sans,8' front noenhanced
set label "0.5mm" at graph 0.584254, graph 0.913303 left font 'Sans,8' front noenhanced
set label "0.25mm" at graph 0.647062, graph 0.915836 left font 'Sans,8' front noenhanced
$pairs_8_0 << EOD
1363 1.67388e-16
EOD
$pairs_8_1 << EOD
1613 1.67388e-16
EOD
$pairs_8_2 << EOD
170 15.1584
EOD
$pairs_8_3 << EOD
1593 0.037277
EOD
$pairs_8_4 << EOD
611 0.976496
EOD
$pairs_8_5 << EOD
2143 0.976496
EOD
$pairs_8_6 << EOD
2956 5.02164e-15
EOD
$pairs_8_7 << EOD
2224 5.49364e-15
EOD
$pairs_8_8 << EOD
2014 1.61924
7124 1.5968
26641 1.64122
111319 1.8235
EOD
$pairs_8_front << EOD
170 15.1584
611 0.976496
1363 1.67388e-16
EOD
plot $pairs_8_front using 1:2 with lines dt 2 lw 2 lc rgb '#888888' title 'Pareto front', \
  $pairs_8_0 using 1:2 with points pt 7 ps 1.6 lc rgb '#1f77b4' title "hapticd-exact-warm" noenhanced, \
  $pairs_8_1 using 1:2 with points pt 5 ps 1.6 lc rgb '#d62728' title "hapticd-exact-cold" noenhanced, \
  $pairs_8_2 using 1:2 with points pt 9 ps 1.6 lc rgb '#2ca02c' title "hapticd-depth-along-motion" noenhanced, \
  $pairs_8_3 using 1:2 with points pt 11 ps 1.6 lc rgb '#9467bd' title "libccd-GJK-EPA" noenhanced, \
  $pairs_8_4 using 1:2 with points pt 13 ps 1.6 lc rgb '#ff7f0e' title "libccd-MPR" noenhanced, \
  $pairs_8_5 using 1:2 with points pt 4 ps 1.6 lc rgb '#8c564b' title "FCL-libccd" noenhanced, \
  $pairs_8_6 using 1:2 with points pt 6 ps 1.6 lc rgb '#e377c2' title "Bullet-btGjkPairDetector" noenhanced, \
  $pairs_8_7 using 1:2 with points pt 8 ps 1.6 lc rgb '#17becf' title "Bullet-btGjkEpaSolver2" noenhanced, \
  $pairs_8_8 using 1:2 with linespoints lw 1.5 pt 10 ps 1.6 lc rgb '#7f7f7f' title "voxel-McNeely, h swept" noenhanced
reset
set terminal pngcairo size 1100,660 font 'Sans,10'
set output "docs/accuracy/pairs_32.png"
set lmargin at screen 0.08
set rmargin at screen 0.63
set bmargin at screen 0.1
set tmargin at screen 0.91
set logscale xy
set grid xtics ytics mxtics mytics lc rgb '#dddddd'
set format x '10^{%L}'
set format y '10^{%L}'
set xrange [146.209:1.77828e+06]
set yrange [6.29794e-17:75.9911]
set xlabel 'median time per query (ns)'
set ylabel 'p99 force error (N)'
set title "What accuracy costs in time: pairs/32" noenhanced
set key at screen 0.65, screen 0.91 left top Left reverse font 'Sans,9' spacing 1.2
set arrow from 1e+06, graph 0 to 1e+06, graph 1 nohead dt 3 lw 1.5 lc rgb '#b00000' back
set label "1 kHz tick" at 1e+06, graph 0.97 right rotate by 90 offset -1.3,0 font 'Sans,8' tc rgb '#b00000'
set arrow from 250000, graph 0 to 250000, graph 1 nohead dt 3 lw 1.5 lc rgb '#b00000' back
set label "4 kHz tick" at 250000, graph 0.97 right rotate by 90 offset -1.3,0 font 'Sans,8' tc rgb '#b00000'
set label "2mm" at graph 0.389816, graph 0.903153 left font 'Sans,8' front noenhanced
set label "1mm" at graph 0.525749, graph 0.906912 left font 'Sans,8' front noenhanced
set label "0.5mm" at graph 0.670539, graph 0.90828 left font 'Sans,8' front noenhanced
set label "0.25mm" at graph 0.822536, graph 0.90844 left font 'Sans,8' front noenhanced
$pairs_32_0 << EOD
2265 5.97475e-15
EOD
$pairs_32_1 << EOD
1954 5.97475e-15
EOD
$pairs_32_2 << EOD
260 19.0881
EOD
$pairs_32_3 << EOD
2836 0.0373738
EOD
$pairs_32_4 << EOD
1243 0.355001
EOD
$pairs_32_5 << EOD
3537 0.324079
EOD
$pairs_32_6 << EOD
4909 8.90573e-15
EOD
$pairs_32_7 << EOD
3577 9.62266e-15
EOD
$pairs_32_8 << EOD
5130 1.34775
18425 1.57608
71925 1.66848
300463 1.67964
EOD
$pairs_32_front << EOD
260 19.0881
1243 0.355001
1954 5.97475e-15
2265 5.97475e-15
EOD
plot $pairs_32_front using 1:2 with lines dt 2 lw 2 lc rgb '#888888' title 'Pareto front', \
  $pairs_32_0 using 1:2 with points pt 7 ps 1.6 lc rgb '#1f77b4' title "hapticd-exact-warm" noenhanced, \
  $pairs_32_1 using 1:2 with points pt 5 ps 1.6 lc rgb '#d62728' title "hapticd-exact-cold" noenhanced, \
  $pairs_32_2 using 1:2 with points pt 9 ps 1.6 lc rgb '#2ca02c' title "hapticd-depth-along-motion" noenhanced, \
  $pairs_32_3 using 1:2 with points pt 11 ps 1.6 lc rgb '#9467bd' title "libccd-GJK-EPA" noenhanced, \
  $pairs_32_4 using 1:2 with points pt 13 ps 1.6 lc rgb '#ff7f0e' title "libccd-MPR" noenhanced, \
  $pairs_32_5 using 1:2 with points pt 4 ps 1.6 lc rgb '#8c564b' title "FCL-libccd" noenhanced, \
  $pairs_32_6 using 1:2 with points pt 6 ps 1.6 lc rgb '#e377c2' title "Bullet-btGjkPairDetector" noenhanced, \
  $pairs_32_7 using 1:2 with points pt 8 ps 1.6 lc rgb '#17becf' title "Bullet-btGjkEpaSolver2" noenhanced, \
  $pairs_32_8 using 1:2 with linespoints lw 1.5 pt 10 ps 1.6 lc rgb '#7f7f7f' title "voxel-McNeely, h swept" noenhanced
reset
set terminal pngcairo size 1100,660 font 'Sans,10'
set output "docs/accuracy/pairs_128.png"
set lmargin at screen 0.08
set rmargin at screen 0.63
set bmargin at screen 0.1
set tmargin at screen 0.91
set logscale xy
set grid xtics ytics mxtics mytics lc rgb '#dddddd'
set format x '10^{%L}'
set format y '10^{%L}'
set xrange [269.924:1.77828e+06]
set yrange [6.37184e-17:77.7993]
set xlabel 'median time per query (ns)'
set ylabel 'p99 force error (N)'
set title "What accuracy costs in time: pairs/128" noenhanced
set key at screen 0.65, screen 0.91 left top Left reverse font 'Sans,9' spacing 1.2
set arrow from 1e+06, graph 0 to 1e+06, graph 1 nohead dt 3 lw 1.5 lc rgb '#b00000' back
set label "1 kHz tick" at 1e+06, graph 0.97 right rotate by 90 offset -1.3,0 font 'Sans,8' tc rgb '#b00000'
set arrow from 250000, graph 0 to 250000, graph 1 nohead dt 3 lw 1.5 lc rgb '#b00000' back
set label "4 kHz tick" at 250000, graph 0.97 right rotate by 90 offset -1.3,0 font 'Sans,8' tc rgb '#b00000'
set label "2mm" at graph 0.371832, graph 0.895944 left font 'Sans,8' front noenhanced
set label "1mm" at graph 0.516069, graph 0.899083 left font 'Sans,8' front noenhanced
set label "0.5mm" at graph 0.668065, graph 0.902287 left font 'Sans,8' front noenhanced
set label "0.25mm" at graph 0.809807, graph 0.927298 left font 'Sans,8' front noenhanced
$pairs_128_0 << EOD
3778 6.14985e-15
EOD
$pairs_128_1 << EOD
3156 6.04486e-15
EOD
$pairs_128_2 << EOD
480 19.5423
EOD
$pairs_128_3 << EOD
7154 0.0339337
EOD
$pairs_128_4 << EOD
4279 0.540271
EOD
$pairs_128_5 << EOD
5029 0.570367
EOD
$pairs_128_6 << EOD
11752 0.00433206
EOD
$pairs_128_7 << EOD
8215 1.38057e-14
EOD
$pairs_128_8 << EOD
6412 1.02081
22793 1.16336
86743 1.32942
433824 1.42276
EOD
$pairs_128_front << EOD
480 19.5423
3156 6.04486e-15
EOD
plot $pairs_128_front using 1:2 with lines dt 2 lw 2 lc rgb '#888888' title 'Pareto front', \
  $pairs_128_0 using 1:2 with points pt 7 ps 1.6 lc rgb '#1f77b4' title "hapticd-exact-warm" noenhanced, \
  $pairs_128_1 using 1:2 with points pt 5 ps 1.6 lc rgb '#d62728' title "hapticd-exact-cold" noenhanced, \
  $pairs_128_2 using 1:2 with points pt 9 ps 1.6 lc rgb '#2ca02c' title "hapticd-depth-along-motion" noenhanced, \
  $pairs_128_3 using 1:2 with points pt 11 ps 1.6 lc rgb '#9467bd' title "libccd-GJK-EPA" noenhanced, \
  $pairs_128_4 using 1:2 with points pt 13 ps 1.6 lc rgb '#ff7f0e' title "libccd-MPR" noenhanced, \
  $pairs_128_5 using 1:2 with points pt 4 ps 1.6 lc rgb '#8c564b' title "FCL-libccd" noenhanced, \
  $pairs_128_6 using 1:2 with points pt 6 ps 1.6 lc rgb '#e377c2' title "Bullet-btGjkPairDetector" noenhanced, \
  $pairs_128_7 using 1:2 with points pt 8 ps 1.6 lc rgb '#17becf' title "Bullet-btGjkEpaSolver2" noenhanced, \
  $pairs_128_8 using 1:2 with linespoints lw 1.5 pt 10 ps 1.6 lc rgb '#7f7f7f' title "voxel-McNeely, h swept" noenhanced
reset
set terminal pngcairo size 1100,660 font 'Sans,10'
set output "docs/accuracy/scene_peg_in_hole.png"
set lmargin at screen 0.08
set rmargin at screen 0.63
set bmargin at screen 0.1
set tmargin at screen 0.91
set logscale xy
set grid xtics ytics mxtics mytics lc rgb '#dddddd'
set format x '10^{%L}'
set format y '10^{%L}'
set xrange [14293.6:1.77828e+06]
set yrange [5.13112e-05:40.5416]
set xlabel 'p99.9 time per tick (ns)'
set ylabel 'p99 force error (N)'
set title "What accuracy costs in time: scene/peg_in_hole" noenhanced
set key at screen 0.65, screen 0.91 left top Left reverse font 'Sans,9' spacing 1.2
set arrow from 1e+06, graph 0 to 1e+06, graph 1 nohead dt 3 lw 1.5 lc rgb '#b00000' back
set label "1 kHz tick" at 1e+06, graph 0.97 right rotate by 90 offset -1.3,0 font 'Sans,8' tc rgb '#b00000'
set arrow from 250000, graph 0 to 250000, graph 1 nohead dt 3 lw 1.5 lc rgb '#b00000' back
set label "4 kHz tick" at 250000, graph 0.97 right rotate by 90 offset -1.3,0 font 'Sans,8' tc rgb '#b00000'
set arrow from graph 0, first 0.00016226 to graph 1, first 0.00016226 nohead dt 2 lc rgb '#999999' back
set label 'no error (exact)' at graph 0.99, first 0.00016226 right offset 0,0.7 font 'Sans,8' tc rgb '#666666'
set label "8" at graph 0.184089, graph 0.108161 left font 'Sans,8' front noenhanced
set label "4" at graph 0.154606, graph 0.084779 left font 'Sans,8' front noenhanced
set label "2" at graph 0.217321, graph 0.084779 left font 'Sans,8' front noenhanced
set label "1" at graph 0.189892, graph 0.061397 left font 'Sans,8' front noenhanced
set label "2 kHz" at graph 0.363988, graph 0.335237 left font 'Sans,8' front noenhanced
set label "4 kHz" at graph 0.251232, graph 0.397419 left font 'Sans,8' front noenhanced
set label "3.32mm" at graph 0.13091, graph 0.880961 left font 'Sans,8' front noenhanced
set label "1.66mm" at graph 0.257097, graph 0.898265 left font 'Sans,8' front noenhanced
set label "0.829mm" at graph 0.399927, graph 0.89156 left font 'Sans,8' front noenhanced
$scene_peg_in_hole_0 << EOD
45234 0.00016226
EOD
$scene_peg_in_hole_1 << EOD
35577 0.00016226
33422 0.00016226
38562 0.00016226
36587 0.00016226
EOD
$scene_peg_in_hole_2 << EOD
63960 0.026241
EOD
$scene_peg_in_hole_3 << EOD
78236 0.00486781
45415 0.0113258
EOD
$scene_peg_in_hole_4 << EOD
25418 8.05094
46718 10.1836
93045 9.29728
EOD
$scene_peg_in_hole_front << EOD
25418 8.05094
33422 0.00016226
EOD
plot $scene_peg_in_hole_front using 1:2 with lines dt 2 lw 2 lc rgb '#888888' title 'Pareto front', \
  $scene_peg_in_hole_0 using 1:2 with points pt 7 ps 1.6 lc rgb '#1f77b4' title "hapticd-tick exact, budget unlimited, δ on (the truth)" noenhanced, \
  $scene_peg_in_hole_1 using 1:2 with linespoints lw 1.5 pt 5 ps 1.6 lc rgb '#d62728' title "hapticd-tick, budget swept" noenhanced, \
  $scene_peg_in_hole_2 using 1:2 with points pt 9 ps 1.6 lc rgb '#2ca02c' title "hapticd-tick δ off" noenhanced, \
  $scene_peg_in_hole_3 using 1:2 with linespoints lw 1.5 pt 11 ps 1.6 lc rgb '#9467bd' title "hapticd-tick, servo rate swept" noenhanced, \
  $scene_peg_in_hole_4 using 1:2 with linespoints lw 1.5 pt 13 ps 1.6 lc rgb '#ff7f0e' title "voxel-McNeely, h swept" noenhanced
reset
set terminal pngcairo size 1100,660 font 'Sans,10'
set output "docs/accuracy/scene_gears.png"
set lmargin at screen 0.08
set rmargin at screen 0.63
set bmargin at screen 0.1
set tmargin at screen 0.91
set logscale xy
set grid xtics ytics mxtics mytics lc rgb '#dddddd'
set format x '10^{%L}'
set format y '10^{%L}'
set xrange [56711:1.77828e+06]
set yrange [1.64798e-05:0.0243855]
set xlabel 'p99.9 time per tick (ns)'
set ylabel 'p99 force error (N)'
set title "What accuracy costs in time: scene/gears" noenhanced
set key at screen 0.65, screen 0.91 left top Left reverse font 'Sans,9' spacing 1.2
set arrow from 1e+06, graph 0 to 1e+06, graph 1 nohead dt 3 lw 1.5 lc rgb '#b00000' back
set label "1 kHz tick" at 1e+06, graph 0.97 right rotate by 90 offset -1.3,0 font 'Sans,8' tc rgb '#b00000'
set arrow from 250000, graph 0 to 250000, graph 1 nohead dt 3 lw 1.5 lc rgb '#b00000' back
set label "4 kHz tick" at 250000, graph 0.97 right rotate by 90 offset -1.3,0 font 'Sans,8' tc rgb '#b00000'
set arrow from graph 0, first 5.21137e-05 to graph 1, first 5.21137e-05 nohead dt 2 lc rgb '#999999' back
set label 'no error (exact)' at graph 0.99, first 5.21137e-05 right offset 0,0.7 font 'Sans,8' tc rgb '#666666'
set label "8" at graph 0.239572, graph 0.623662 left font 'Sans,8' front noenhanced
set label "4" at graph 0.272485, graph 0.731976 left font 'Sans,8' front noenhanced
set label "2" at graph 0.178645, graph 0.810736 left font 'Sans,8' front noenhanced
set label "1" at graph 0.247321, graph 0.802952 left font 'Sans,8' front noenhanced
set label "2 kHz" at graph 0.354111, graph 0.736547 left font 'Sans,8' front noenhanced
set label "4 kHz" at graph 0.479028, graph 0.743712 left font 'Sans,8' front noenhanced
$scene_gears_0 << EOD
115076 5.21137e-05
EOD
$scene_gears_1 << EOD
124404 0.00156341
139342 0.00344705
100848 0.00612535
127770 0.00578698
EOD
$scene_gears_2 << EOD
152997 5.21137e-05
EOD
$scene_gears_3 << EOD
184596 0.00356399
283883 0.00375535
EOD
$scene_gears_front << EOD
100848 0.00612535
115076 5.21137e-05
EOD
plot $scene_gears_front using 1:2 with lines dt 2 lw 2 lc rgb '#888888' title 'Pareto front', \
  $scene_gears_0 using 1:2 with points pt 7 ps 1.6 lc rgb '#1f77b4' title "hapticd-tick exact, budget unlimited, δ on (the truth)" noenhanced, \
  $scene_gears_1 using 1:2 with linespoints lw 1.5 pt 5 ps 1.6 lc rgb '#d62728' title "hapticd-tick, budget swept" noenhanced, \
  $scene_gears_2 using 1:2 with points pt 9 ps 1.6 lc rgb '#2ca02c' title "hapticd-tick δ off" noenhanced, \
  $scene_gears_3 using 1:2 with linespoints lw 1.5 pt 11 ps 1.6 lc rgb '#9467bd' title "hapticd-tick, servo rate swept" noenhanced
reset
set terminal pngcairo size 1100,660 font 'Sans,10'
set output "docs/accuracy/scene_dynamic.png"
set lmargin at screen 0.08
set rmargin at screen 0.63
set bmargin at screen 0.1
set tmargin at screen 0.91
set logscale xy
set grid xtics ytics mxtics mytics lc rgb '#dddddd'
set format x '10^{%L}'
set format y '10^{%L}'
set xrange [11869.9:1.77828e+06]
set yrange [0.00171883:31.3554]
set xlabel 'p99.9 time per tick (ns)'
set ylabel 'p99 force error (N)'
set title "What accuracy costs in time: scene/dynamic" noenhanced
set key at screen 0.65, screen 0.91 left top Left reverse font 'Sans,9' spacing 1.2
set arrow from 1e+06, graph 0 to 1e+06, graph 1 nohead dt 3 lw 1.5 lc rgb '#b00000' back
set label "1 kHz tick" at 1e+06, graph 0.97 right rotate by 90 offset -1.3,0 font 'Sans,8' tc rgb '#b00000'
set arrow from 250000, graph 0 to 250000, graph 1 nohead dt 3 lw 1.5 lc rgb '#b00000' back
set label "4 kHz tick" at 250000, graph 0.97 right rotate by 90 offset -1.3,0 font 'Sans,8' tc rgb '#b00000'
set arrow from graph 0, first 0.00543543 to graph 1, first 0.00543543 nohead dt 2 lc rgb '#999999' back
set label 'no error (exact)' at graph 0.99, first 0.00543543 right offset 0,0.7 font 'Sans,8' tc rgb '#666666'
set label "8" at graph 0.483813, graph 0.463995 left font 'Sans,8' front noenhanced
set label "4" at graph 0.547489, graph 0.51373 left font 'Sans,8' front noenhanced
set label "2" at graph 0.554171, graph 0.812521 left font 'Sans,8' front noenhanced
set label "1" at graph 0.528146, graph 0.859191 left font 'Sans,8' front noenhanced
set label "2 kHz" at graph 0.479337, graph 0.731879 left font 'Sans,8' front noenhanced
set label "4 kHz" at graph 0.421514, graph 0.788481 left font 'Sans,8' front noenhanced
set label "7.63mm" at graph 0.126484, graph 0.117341 left font 'Sans,8' front noenhanced
set label "3.82mm" at graph 0.263205, graph 0.117341 left font 'Sans,8' front noenhanced
set label "1.91mm" at graph 0.331716, graph 0.117341 left font 'Sans,8' front noenhanced
$scene_dynamic_0 << EOD
122430 0.00543543
EOD
$scene_dynamic_1 << EOD
126426 0.163063
173927 0.26563
179847 4.98252
157865 7.87613
EOD
$scene_dynamic_2 << EOD
132919 1.26781
EOD
$scene_dynamic_3 << EOD
123623 2.25854
92534 3.93564
EOD
$scene_dynamic_4 << EOD
21108 0.00543543
41869 0.00543543
89277 0.00543543
EOD
$scene_dynamic_front << EOD
21108 0.00543543
122430 0.00543543
EOD
plot $scene_dynamic_front using 1:2 with lines dt 2 lw 2 lc rgb '#888888' title 'Pareto front', \
  $scene_dynamic_0 using 1:2 with points pt 7 ps 1.6 lc rgb '#1f77b4' title "hapticd-tick exact, budget unlimited, δ on (the truth)" noenhanced, \
  $scene_dynamic_1 using 1:2 with linespoints lw 1.5 pt 5 ps 1.6 lc rgb '#d62728' title "hapticd-tick, budget swept" noenhanced, \
  $scene_dynamic_2 using 1:2 with points pt 9 ps 1.6 lc rgb '#2ca02c' title "hapticd-tick δ off" noenhanced, \
  $scene_dynamic_3 using 1:2 with linespoints lw 1.5 pt 11 ps 1.6 lc rgb '#9467bd' title "hapticd-tick, servo rate swept" noenhanced, \
  $scene_dynamic_4 using 1:2 with linespoints lw 1.5 pt 13 ps 1.6 lc rgb '#ff7f0e' title "voxel-McNeely, h swept" noenhanced
reset
set terminal pngcairo size 1100,660 font 'Sans,10'
set output "docs/accuracy/scene_stress.png"
set lmargin at screen 0.08
set rmargin at screen 0.63
set bmargin at screen 0.1
set tmargin at screen 0.91
set logscale xy
set grid xtics ytics mxtics mytics lc rgb '#dddddd'
set format x '10^{%L}'
set format y '10^{%L}'
set xrange [84013.8:1.77828e+06]
set yrange [0.0357019:38.942]
set xlabel 'p99.9 time per tick (ns)'
set ylabel 'p99 force error (N)'
set title "What accuracy costs in time: scene/stress" noenhanced
set key at screen 0.65, screen 0.91 left top Left reverse font 'Sans,9' spacing 1.2
set arrow from 1e+06, graph 0 to 1e+06, graph 1 nohead dt 3 lw 1.5 lc rgb '#b00000' back
set label "1 kHz tick" at 1e+06, graph 0.97 right rotate by 90 offset -1.3,0 font 'Sans,8' tc rgb '#b00000'
set arrow from 250000, graph 0 to 250000, graph 1 nohead dt 3 lw 1.5 lc rgb '#b00000' back
set label "4 kHz tick" at 250000, graph 0.97 right rotate by 90 offset -1.3,0 font 'Sans,8' tc rgb '#b00000'
set arrow from graph 0, first 0.112899 to graph 1, first 0.112899 nohead dt 2 lc rgb '#999999' back
set label 'no error (exact)' at graph 0.99, first 0.112899 right offset 0,0.7 font 'Sans,8' tc rgb '#666666'
set label "8" at graph 0.785616, graph 0.747858 left font 'Sans,8' front noenhanced
set label "4" at graph 0.603351, graph 0.747858 left font 'Sans,8' front noenhanced
set label "2" at graph 0.49704, graph 0.739205 left font 'Sans,8' front noenhanced
set label "1" at graph 0.450565, graph 0.740916 left font 'Sans,8' front noenhanced
set label "0.003" at graph 0.62621, graph 0.765642 left font 'Sans,8' front noenhanced
set label "0.01" at graph 0.638122, graph 0.824274 left font 'Sans,8' front noenhanced
set label "0.03" at graph 0.545515, graph 0.802484 left font 'Sans,8' front noenhanced
set label "2 kHz" at graph 0.737927, graph 0.797778 left font 'Sans,8' front noenhanced
set label "4 kHz" at graph 0.568642, graph 0.838526 left font 'Sans,8' front noenhanced
$scene_stress_0 << EOD
633539 0.112899
EOD
$scene_stress_1 << EOD
892203 6.67545
511499 6.67545
369754 6.2834
320851 6.35902
EOD
$scene_stress_2 << EOD
740187 9.75087
EOD
$scene_stress_3 << EOD
612849 8.90289
625994 9.67346
519324 9.78178
EOD
$scene_stress_4 << EOD
963066 9.46505
574438 9.75215
EOD
$scene_stress_5 << EOD
149400 3.38698
EOD
$scene_stress_front << EOD
149400 3.38698
633539 0.112899
EOD
plot $scene_stress_front using 1:2 with lines dt 2 lw 2 lc rgb '#888888' title 'Pareto front', \
  $scene_stress_0 using 1:2 with points pt 7 ps 1.6 lc rgb '#1f77b4' title "hapticd-tick exact, budget unlimited, δ on (the truth)" noenhanced, \
  $scene_stress_1 using 1:2 with linespoints lw 1.5 pt 5 ps 1.6 lc rgb '#d62728' title "hapticd-tick, budget swept" noenhanced, \
  $scene_stress_2 using 1:2 with points pt 9 ps 1.6 lc rgb '#2ca02c' title "hapticd-tick δ off" noenhanced, \
  $scene_stress_3 using 1:2 with linespoints lw 1.5 pt 11 ps 1.6 lc rgb '#9467bd' title "hapticd-tick, tessellation swept" noenhanced, \
  $scene_stress_4 using 1:2 with linespoints lw 1.5 pt 13 ps 1.6 lc rgb '#ff7f0e' title "hapticd-tick, servo rate swept" noenhanced, \
  $scene_stress_5 using 1:2 with points pt 4 ps 1.6 lc rgb '#8c564b' title "voxel-McNeely, h swept" noenhanced
