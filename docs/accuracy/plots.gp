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
set xrange [56.2341:1.77828e+06]
set yrange [5.29327e-17:60.3468]
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
set label "2mm" at graph 0.264989, graph 0.912978 left font 'Sans,8' front noenhanced
set label "1mm" at graph 0.444501, graph 0.912643 left font 'Sans,8' front noenhanced
set label "0.5mm" at graph 0.572062, graph 0.913303 left font 'Sans,8' front noenhanced
set label "0.25mm" at graph 0.70286, graph 0.915836 left font 'Sans,8' front noenhanced
$pairs_8_0 << EOD
963 1.67388e-16
EOD
$pairs_8_1 << EOD
1153 1.67388e-16
EOD
$pairs_8_2 << EOD
100 15.1584
EOD
$pairs_8_3 << EOD
1094 0.037277
EOD
$pairs_8_4 << EOD
482 0.976496
EOD
$pairs_8_5 << EOD
1674 0.976496
EOD
$pairs_8_6 << EOD
2135 5.02164e-15
EOD
$pairs_8_7 << EOD
1624 5.49364e-15
EOD
$pairs_8_8 << EOD
1344 1.61924
4991 1.5968
18716 1.64122
72578 1.8235
EOD
$pairs_8_front << EOD
100 15.1584
482 0.976496
963 1.67388e-16
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
set xrange [107.97:1.77828e+06]
set yrange [6.29794e-17:75.9909]
set xlabel 'median time per query (ns)'
set ylabel 'p99 force error (N)'
set title "What accuracy costs in time: pairs/32" noenhanced
set key at screen 0.65, screen 0.91 left top Left reverse font 'Sans,9' spacing 1.2
set arrow from 1e+06, graph 0 to 1e+06, graph 1 nohead dt 3 lw 1.5 lc rgb '#b00000' back
set label "1 kHz tick" at 1e+06, graph 0.97 right rotate by 90 offset -1.3,0 font 'Sans,8' tc rgb '#b00000'
set arrow from 250000, graph 0 to 250000, graph 1 nohead dt 3 lw 1.5 lc rgb '#b00000' back
set label "4 kHz tick" at 250000, graph 0.97 right rotate by 90 offset -1.3,0 font 'Sans,8' tc rgb '#b00000'
set label "2mm" at graph 0.370964, graph 0.903153 left font 'Sans,8' front noenhanced
set label "1mm" at graph 0.508474, graph 0.906912 left font 'Sans,8' front noenhanced
set label "0.5mm" at graph 0.644657, graph 0.90828 left font 'Sans,8' front noenhanced
set label "0.25mm" at graph 0.706549, graph 0.90844 left font 'Sans,8' front noenhanced
$pairs_32_0 << EOD
1725 5.97475e-15
EOD
$pairs_32_1 << EOD
1514 5.97475e-15
EOD
$pairs_32_2 << EOD
192 19.0881
EOD
$pairs_32_3 << EOD
2055 0.0373738
EOD
$pairs_32_4 << EOD
1004 0.355001
EOD
$pairs_32_5 << EOD
2836 0.324079
EOD
$pairs_32_6 << EOD
3808 8.90573e-15
EOD
$pairs_32_7 << EOD
2856 9.62266e-15
EOD
$pairs_32_8 << EOD
3538 1.34775
13446 1.57608
50447 1.66848
205261 1.67964
EOD
$pairs_32_front << EOD
192 19.0881
1004 0.355001
1514 5.97475e-15
1725 5.97475e-15
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
set xrange [282.295:1.77828e+06]
set yrange [6.37184e-17:77.7992]
set xlabel 'median time per query (ns)'
set ylabel 'p99 force error (N)'
set title "What accuracy costs in time: pairs/128" noenhanced
set key at screen 0.65, screen 0.91 left top Left reverse font 'Sans,9' spacing 1.2
set arrow from 1e+06, graph 0 to 1e+06, graph 1 nohead dt 3 lw 1.5 lc rgb '#b00000' back
set label "1 kHz tick" at 1e+06, graph 0.97 right rotate by 90 offset -1.3,0 font 'Sans,8' tc rgb '#b00000'
set arrow from 250000, graph 0 to 250000, graph 1 nohead dt 3 lw 1.5 lc rgb '#b00000' back
set label "4 kHz tick" at 250000, graph 0.97 right rotate by 90 offset -1.3,0 font 'Sans,8' tc rgb '#b00000'
set label "2mm" at graph 0.352893, graph 0.895944 left font 'Sans,8' front noenhanced
set label "1mm" at graph 0.49864, graph 0.899083 left font 'Sans,8' front noenhanced
set label "0.5mm" at graph 0.646728, graph 0.902287 left font 'Sans,8' front noenhanced
set label "0.25mm" at graph 0.812713, graph 0.903916 left font 'Sans,8' front noenhanced
$pairs_128_0 << EOD
3868 6.14985e-15
EOD
$pairs_128_1 << EOD
3408 6.04486e-15
EOD
$pairs_128_2 << EOD
502 19.5423
EOD
$pairs_128_3 << EOD
7746 0.0339337
EOD
$pairs_128_4 << EOD
3868 0.540271
EOD
$pairs_128_5 << EOD
4871 0.570367
EOD
$pairs_128_6 << EOD
11593 0.00433206
EOD
$pairs_128_7 << EOD
8507 1.38057e-14
EOD
$pairs_128_8 << EOD
5591 1.02081
20009 1.16336
73090 1.32942
312235 1.42276
EOD
$pairs_128_front << EOD
502 19.5423
3408 6.04486e-15
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
set xrange [29967.7:1.77828e+06]
set yrange [4.05092e-19:38.6461]
set xlabel 'p99.9 time per tick (ns)'
set ylabel 'p99 force error (N)'
set title "What accuracy costs in time: scene/peg_in_hole" noenhanced
set key at screen 0.65, screen 0.91 left top Left reverse font 'Sans,9' spacing 1.2
set arrow from 1e+06, graph 0 to 1e+06, graph 1 nohead dt 3 lw 1.5 lc rgb '#b00000' back
set label "1 kHz tick" at 1e+06, graph 0.97 right rotate by 90 offset -1.3,0 font 'Sans,8' tc rgb '#b00000'
set arrow from 250000, graph 0 to 250000, graph 1 nohead dt 3 lw 1.5 lc rgb '#b00000' back
set label "4 kHz tick" at 250000, graph 0.97 right rotate by 90 offset -1.3,0 font 'Sans,8' tc rgb '#b00000'
set arrow from graph 0, first 1.28101e-18 to graph 1, first 1.28101e-18 nohead dt 2 lc rgb '#999999' back
set label 'no error (exact)' at graph 0.99, first 1.28101e-18 right offset 0,0.7 font 'Sans,8' tc rgb '#666666'
set label "8" at graph 0.170922, graph 0.0250256 left font 'Sans,8' front noenhanced
set label "4" at graph 0.186589, graph 0.0484076 left font 'Sans,8' front noenhanced
set label "2" at graph 0.172395, graph 0.661427 left font 'Sans,8' front noenhanced
set label "1" at graph 0.20558, graph 0.867265 left font 'Sans,8' front noenhanced
set label "2 kHz" at graph 0.110831, graph 0.8048 left font 'Sans,8' front noenhanced
set label "4 kHz" at graph 0.191384, graph 0.823162 left font 'Sans,8' front noenhanced
set label "3.32mm" at graph 0.152547, graph 0.961102 left font 'Sans,8' front noenhanced
set label "1.66mm" at graph 0.236407, graph 0.969969 left font 'Sans,8' front noenhanced
set label "0.829mm" at graph 0.363402, graph 0.968532 left font 'Sans,8' front noenhanced
$scene_peg_in_hole_0 << EOD
68069 1.28101e-18
EOD
$scene_peg_in_hole_1 << EOD
65745 1.28101e-18
65514 1.28101e-18
57790 6.64617e-06
66176 0.0861223
EOD
$scene_peg_in_hole_2 << EOD
61978 0.0262429
EOD
$scene_peg_in_hole_3 << EOD
60485 0.00486519
62449 0.0113228
EOD
$scene_peg_in_hole_4 << EOD
88408 0.85526
EOD
$scene_peg_in_hole_5 << EOD
80853 1.83373e-15
EOD
$scene_peg_in_hole_6 << EOD
75784 5.79561e-16
EOD
$scene_peg_in_hole_7 << EOD
68740 3.84304e-17
EOD
$scene_peg_in_hole_8 << EOD
53291 6.45556
75053 9.70746
126059 9.08618
EOD
$scene_peg_in_hole_front << EOD
53291 6.45556
57790 6.64617e-06
65514 1.28101e-18
EOD
plot $scene_peg_in_hole_front using 1:2 with lines dt 2 lw 2 lc rgb '#888888' title 'Pareto front', \
  $scene_peg_in_hole_0 using 1:2 with points pt 7 ps 1.6 lc rgb '#1f77b4' title "hapticd-tick exact, budget unlimited, δ on (the truth)" noenhanced, \
  $scene_peg_in_hole_1 using 1:2 with linespoints lw 1.5 pt 5 ps 1.6 lc rgb '#d62728' title "hapticd-tick, budget swept" noenhanced, \
  $scene_peg_in_hole_2 using 1:2 with points pt 9 ps 1.6 lc rgb '#2ca02c' title "hapticd-tick δ off" noenhanced, \
  $scene_peg_in_hole_3 using 1:2 with linespoints lw 1.5 pt 11 ps 1.6 lc rgb '#9467bd' title "hapticd-tick, servo rate swept" noenhanced, \
  $scene_peg_in_hole_4 using 1:2 with points pt 13 ps 1.6 lc rgb '#ff7f0e' title "hapticd-depth-along-motion closed loop" noenhanced, \
  $scene_peg_in_hole_5 using 1:2 with points pt 4 ps 1.6 lc rgb '#8c564b' title "FCL-libccd closed loop" noenhanced, \
  $scene_peg_in_hole_6 using 1:2 with points pt 6 ps 1.6 lc rgb '#e377c2' title "Bullet-btGjkPairDetector closed loop" noenhanced, \
  $scene_peg_in_hole_7 using 1:2 with points pt 8 ps 1.6 lc rgb '#17becf' title "Bullet-btGjkEpaSolver2 closed loop" noenhanced, \
  $scene_peg_in_hole_8 using 1:2 with linespoints lw 1.5 pt 10 ps 1.6 lc rgb '#7f7f7f' title "voxel-McNeely, h swept" noenhanced
reset
set terminal pngcairo size 1100,660 font 'Sans,10'
set output "docs/accuracy/shaping_peg_in_hole.png"
set lmargin at screen 0.08
set rmargin at screen 0.63
set bmargin at screen 0.1
set tmargin at screen 0.91
set logscale xy
set grid xtics ytics mxtics mytics lc rgb '#dddddd'
set format x '10^{%L}'
set format y '10^{%L}'
set xrange [32520.2:1.77828e+06]
set yrange [0.0105409:3.98107]
set xlabel 'p99.9 time per tick (ns)'
set ylabel 'p99 force error (N)'
set title "What accuracy costs in time: shaping/peg_in_hole" noenhanced
set key at screen 0.65, screen 0.91 left top Left reverse font 'Sans,9' spacing 1.2
set arrow from 1e+06, graph 0 to 1e+06, graph 1 nohead dt 3 lw 1.5 lc rgb '#b00000' back
set label "1 kHz tick" at 1e+06, graph 0.97 right rotate by 90 offset -1.3,0 font 'Sans,8' tc rgb '#b00000'
set arrow from 250000, graph 0 to 250000, graph 1 nohead dt 3 lw 1.5 lc rgb '#b00000' back
set label "4 kHz tick" at 250000, graph 0.97 right rotate by 90 offset -1.3,0 font 'Sans,8' tc rgb '#b00000'
set arrow from graph 0, first 0.0333333 to graph 1, first 0.0333333 nohead dt 2 lc rgb '#999999' back
set label 'no error (exact)' at graph 0.99, first 0.0333333 right offset 0,0.7 font 'Sans,8' tc rgb '#666666'
set label "0.1 N/tick" at graph 0.114714, graph 0.217397 left font 'Sans,8' front noenhanced
set label "0.25 N/tick" at graph 0.106743, graph 0.170633 left font 'Sans,8' front noenhanced
set label "0.5 N/tick (default)" at graph 0.174389, graph 0.230491 left font 'Sans,8' front noenhanced
set label "2 N/tick" at graph 0.178682, graph 0.157539 left font 'Sans,8' front noenhanced
set label "0° (shading off)" at graph 0.159768, graph 0.174374 left font 'Sans,8' front noenhanced
set label "20°" at graph 0.0926165, graph 0.194015 left font 'Sans,8' front noenhanced
set label "60°" at graph 0.0989443, graph 0.230491 left font 'Sans,8' front noenhanced
set label "85°" at graph 0.195355, graph 0.194015 left font 'Sans,8' front noenhanced
$shaping_peg_in_hole_0 << EOD
67577 0.0333333
EOD
$shaping_peg_in_hole_1 << EOD
62760 0.0333333
62008 0.0333333
62389 0.0333333
63470 0.0333333
EOD
$shaping_peg_in_hole_2 << EOD
59234 0.0333333
57830 0.0333333
59313 0.0333333
67849 0.0333333
EOD
$shaping_peg_in_hole_front << EOD
57830 0.0333333
EOD
plot $shaping_peg_in_hole_front using 1:2 with lines dt 2 lw 2 lc rgb '#888888' title 'Pareto front', \
  $shaping_peg_in_hole_0 using 1:2 with points pt 7 ps 1.6 lc rgb '#1f77b4' title "hapticd-tick no step limit, shading 40° (the truth)" noenhanced, \
  $shaping_peg_in_hole_1 using 1:2 with linespoints lw 1.5 pt 5 ps 1.6 lc rgb '#d62728' title "hapticd-tick, F_max swept" noenhanced, \
  $shaping_peg_in_hole_2 using 1:2 with linespoints lw 1.5 pt 9 ps 1.6 lc rgb '#2ca02c' title "hapticd-tick, crease angle swept" noenhanced
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
set xrange [53366.8:1.77828e+06]
set yrange [3.47198e-05:0.23781]
set xlabel 'p99.9 time per tick (ns)'
set ylabel 'p99 force error (N)'
set title "What accuracy costs in time: scene/gears" noenhanced
set key at screen 0.65, screen 0.91 left top Left reverse font 'Sans,9' spacing 1.2
set arrow from 1e+06, graph 0 to 1e+06, graph 1 nohead dt 3 lw 1.5 lc rgb '#b00000' back
set label "1 kHz tick" at 1e+06, graph 0.97 right rotate by 90 offset -1.3,0 font 'Sans,8' tc rgb '#b00000'
set arrow from 250000, graph 0 to 250000, graph 1 nohead dt 3 lw 1.5 lc rgb '#b00000' back
set label "4 kHz tick" at 250000, graph 0.97 right rotate by 90 offset -1.3,0 font 'Sans,8' tc rgb '#b00000'
set arrow from graph 0, first 0.000109794 to graph 1, first 0.000109794 nohead dt 2 lc rgb '#999999' back
set label 'no error (exact)' at graph 0.99, first 0.000109794 right offset 0,0.7 font 'Sans,8' tc rgb '#666666'
set label "8" at graph 0.191094, graph 0.130356 left font 'Sans,8' front noenhanced
set label "4" at graph 0.201442, graph 0.515459 left font 'Sans,8' front noenhanced
set label "2" at graph 0.168908, graph 0.530972 left font 'Sans,8' front noenhanced
set label "1" at graph 0.189217, graph 0.565235 left font 'Sans,8' front noenhanced
set label "2 kHz" at graph 0.203145, graph 0.482963 left font 'Sans,8' front noenhanced
set label "4 kHz" at graph 0.228811, graph 0.545431 left font 'Sans,8' front noenhanced
$scene_gears_0 << EOD
116250 0.000109794
EOD
$scene_gears_1 << EOD
112454 0.000109794
103847 0.00329381
104038 0.00377749
99490 0.0051124
EOD
$scene_gears_2 << EOD
94901 0.000109794
EOD
$scene_gears_3 << EOD
104469 0.00341166
114306 0.00429202
EOD
$scene_gears_4 << EOD
108365 0.0597352
EOD
$scene_gears_5 << EOD
156106 0.0100874
EOD
$scene_gears_6 << EOD
149675 0.00790289
EOD
$scene_gears_7 << EOD
134986 0.00580962
EOD
$scene_gears_front << EOD
94901 0.000109794
EOD
plot $scene_gears_front using 1:2 with lines dt 2 lw 2 lc rgb '#888888' title 'Pareto front', \
  $scene_gears_0 using 1:2 with points pt 7 ps 1.6 lc rgb '#1f77b4' title "hapticd-tick exact, budget unlimited, δ on (the truth)" noenhanced, \
  $scene_gears_1 using 1:2 with linespoints lw 1.5 pt 5 ps 1.6 lc rgb '#d62728' title "hapticd-tick, budget swept" noenhanced, \
  $scene_gears_2 using 1:2 with points pt 9 ps 1.6 lc rgb '#2ca02c' title "hapticd-tick δ off" noenhanced, \
  $scene_gears_3 using 1:2 with linespoints lw 1.5 pt 11 ps 1.6 lc rgb '#9467bd' title "hapticd-tick, servo rate swept" noenhanced, \
  $scene_gears_4 using 1:2 with points pt 13 ps 1.6 lc rgb '#ff7f0e' title "hapticd-depth-along-motion closed loop" noenhanced, \
  $scene_gears_5 using 1:2 with points pt 4 ps 1.6 lc rgb '#8c564b' title "FCL-libccd closed loop" noenhanced, \
  $scene_gears_6 using 1:2 with points pt 6 ps 1.6 lc rgb '#e377c2' title "Bullet-btGjkPairDetector closed loop" noenhanced, \
  $scene_gears_7 using 1:2 with points pt 8 ps 1.6 lc rgb '#17becf' title "Bullet-btGjkEpaSolver2 closed loop" noenhanced
reset
set terminal pngcairo size 1100,660 font 'Sans,10'
set output "docs/accuracy/shaping_gears.png"
set lmargin at screen 0.08
set rmargin at screen 0.63
set bmargin at screen 0.1
set tmargin at screen 0.91
set logscale xy
set grid xtics ytics mxtics mytics lc rgb '#dddddd'
set format x '10^{%L}'
set format y '10^{%L}'
set xrange [54245.1:1.77828e+06]
set yrange [0.0105409:3.98107]
set xlabel 'p99.9 time per tick (ns)'
set ylabel 'p99 force error (N)'
set title "What accuracy costs in time: shaping/gears" noenhanced
set key at screen 0.65, screen 0.91 left top Left reverse font 'Sans,9' spacing 1.2
set arrow from 1e+06, graph 0 to 1e+06, graph 1 nohead dt 3 lw 1.5 lc rgb '#b00000' back
set label "1 kHz tick" at 1e+06, graph 0.97 right rotate by 90 offset -1.3,0 font 'Sans,8' tc rgb '#b00000'
set arrow from 250000, graph 0 to 250000, graph 1 nohead dt 3 lw 1.5 lc rgb '#b00000' back
set label "4 kHz tick" at 250000, graph 0.97 right rotate by 90 offset -1.3,0 font 'Sans,8' tc rgb '#b00000'
set arrow from graph 0, first 0.0333333 to graph 1, first 0.0333333 nohead dt 2 lc rgb '#999999' back
set label 'no error (exact)' at graph 0.99, first 0.0333333 right offset 0,0.7 font 'Sans,8' tc rgb '#666666'
set label "0.1 N/tick" at graph 0.120725, graph 0.217397 left font 'Sans,8' front noenhanced
set label "0.25 N/tick" at graph 0.208981, graph 0.194015 left font 'Sans,8' front noenhanced
set label "0.5 N/tick (default)" at graph 0.0857417, graph 0.170633 left font 'Sans,8' front noenhanced
set label "2 N/tick" at graph 0.197318, graph 0.230491 left font 'Sans,8' front noenhanced
set label "0° (shading off)" at graph 0.182266, graph 0.157539 left font 'Sans,8' front noenhanced
set label "20°" at graph 0.115404, graph 0.194015 left font 'Sans,8' front noenhanced
set label "60°" at graph 0.118433, graph 0.230491 left font 'Sans,8' front noenhanced
set label "85°" at graph 0.137293, graph 0.157539 left font 'Sans,8' front noenhanced
$shaping_gears_0 << EOD
96463 0.0333333
EOD
$shaping_gears_1 << EOD
98286 0.0333333
108035 0.0333333
103425 0.0333333
103726 0.0333333
EOD
$shaping_gears_2 << EOD
98418 0.0333333
97036 0.0333333
98067 0.0333333
104739 0.0333333
EOD
$shaping_gears_front << EOD
96463 0.0333333
EOD
plot $shaping_gears_front using 1:2 with lines dt 2 lw 2 lc rgb '#888888' title 'Pareto front', \
  $shaping_gears_0 using 1:2 with points pt 7 ps 1.6 lc rgb '#1f77b4' title "hapticd-tick no step limit, shading 40° (the truth)" noenhanced, \
  $shaping_gears_1 using 1:2 with linespoints lw 1.5 pt 5 ps 1.6 lc rgb '#d62728' title "hapticd-tick, F_max swept" noenhanced, \
  $shaping_gears_2 using 1:2 with linespoints lw 1.5 pt 9 ps 1.6 lc rgb '#2ca02c' title "hapticd-tick, crease angle swept" noenhanced
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
set xrange [20941.6:1.77828e+06]
set yrange [9.81645e-05:39.8107]
set xlabel 'p99.9 time per tick (ns)'
set ylabel 'p99 force error (N)'
set title "What accuracy costs in time: scene/dynamic" noenhanced
set key at screen 0.65, screen 0.91 left top Left reverse font 'Sans,9' spacing 1.2
set arrow from 1e+06, graph 0 to 1e+06, graph 1 nohead dt 3 lw 1.5 lc rgb '#b00000' back
set label "1 kHz tick" at 1e+06, graph 0.97 right rotate by 90 offset -1.3,0 font 'Sans,8' tc rgb '#b00000'
set arrow from 250000, graph 0 to 250000, graph 1 nohead dt 3 lw 1.5 lc rgb '#b00000' back
set label "4 kHz tick" at 250000, graph 0.97 right rotate by 90 offset -1.3,0 font 'Sans,8' tc rgb '#b00000'
set arrow from graph 0, first 0.000310424 to graph 1, first 0.000310424 nohead dt 2 lc rgb '#999999' back
set label 'no error (exact)' at graph 0.99, first 0.000310424 right offset 0,0.7 font 'Sans,8' tc rgb '#666666'
set label "8" at graph 0.288273, graph 0.825086 left font 'Sans,8' front noenhanced
set label "4" at graph 0.269525, graph 0.575553 left font 'Sans,8' front noenhanced
set label "2" at graph 0.263686, graph 0.352551 left font 'Sans,8' front noenhanced
set label "1" at graph 0.321155, graph 0.893011 left font 'Sans,8' front noenhanced
set label "2 kHz" at graph 0.265193, graph 0.700781 left font 'Sans,8' front noenhanced
set label "4 kHz" at graph 0.252815, graph 0.744218 left font 'Sans,8' front noenhanced
set label "7.63mm" at graph 0.0585271, graph 0.470904 left font 'Sans,8' front noenhanced
set label "3.82mm" at graph 0.198691, graph 0.470904 left font 'Sans,8' front noenhanced
set label "1.91mm" at graph 0.296103, graph 0.470904 left font 'Sans,8' front noenhanced
$scene_dynamic_0 << EOD
71174 0.000310424
EOD
$scene_dynamic_1 << EOD
71576 4.15982
65857 0.165836
64171 0.00931271
95932 10
EOD
$scene_dynamic_2 << EOD
66937 0.0969043
EOD
$scene_dynamic_3 << EOD
64602 0.835535
61146 1.46407
EOD
$scene_dynamic_4 << EOD
100020 10
EOD
$scene_dynamic_5 << EOD
123364 2.9978
EOD
$scene_dynamic_6 << EOD
163280 1.07104
EOD
$scene_dynamic_7 << EOD
95620 0.944417
EOD
$scene_dynamic_8 << EOD
37240 0.0429345
48080 0.0429345
74109 0.0429345
EOD
$scene_dynamic_front << EOD
37240 0.0429345
64171 0.00931271
71174 0.000310424
EOD
plot $scene_dynamic_front using 1:2 with lines dt 2 lw 2 lc rgb '#888888' title 'Pareto front', \
  $scene_dynamic_0 using 1:2 with points pt 7 ps 1.6 lc rgb '#1f77b4' title "hapticd-tick exact, budget unlimited, δ on (the truth)" noenhanced, \
  $scene_dynamic_1 using 1:2 with linespoints lw 1.5 pt 5 ps 1.6 lc rgb '#d62728' title "hapticd-tick, budget swept" noenhanced, \
  $scene_dynamic_2 using 1:2 with points pt 9 ps 1.6 lc rgb '#2ca02c' title "hapticd-tick δ off" noenhanced, \
  $scene_dynamic_3 using 1:2 with linespoints lw 1.5 pt 11 ps 1.6 lc rgb '#9467bd' title "hapticd-tick, servo rate swept" noenhanced, \
  $scene_dynamic_4 using 1:2 with points pt 13 ps 1.6 lc rgb '#ff7f0e' title "hapticd-depth-along-motion closed loop" noenhanced, \
  $scene_dynamic_5 using 1:2 with points pt 4 ps 1.6 lc rgb '#8c564b' title "FCL-libccd closed loop" noenhanced, \
  $scene_dynamic_6 using 1:2 with points pt 6 ps 1.6 lc rgb '#e377c2' title "Bullet-btGjkPairDetector closed loop" noenhanced, \
  $scene_dynamic_7 using 1:2 with points pt 8 ps 1.6 lc rgb '#17becf' title "Bullet-btGjkEpaSolver2 closed loop" noenhanced, \
  $scene_dynamic_8 using 1:2 with linespoints lw 1.5 pt 10 ps 1.6 lc rgb '#7f7f7f' title "voxel-McNeely, h swept" noenhanced
reset
set terminal pngcairo size 1100,660 font 'Sans,10'
set output "docs/accuracy/dynamics_dynamic.png"
set lmargin at screen 0.08
set rmargin at screen 0.63
set bmargin at screen 0.1
set tmargin at screen 0.91
set logscale xy
set grid xtics ytics mxtics mytics lc rgb '#dddddd'
set format x '10^{%L}'
set format y '10^{%L}'
set xrange [28473.6:1.77828e+06]
set yrange [0.0537575:26.945]
set xlabel 'p99.9 time per tick (ns)'
set ylabel 'p99 force error (N)'
set title "What accuracy costs in time: dynamics/dynamic" noenhanced
set key at screen 0.65, screen 0.91 left top Left reverse font 'Sans,9' spacing 1.2
set arrow from 1e+06, graph 0 to 1e+06, graph 1 nohead dt 3 lw 1.5 lc rgb '#b00000' back
set label "1 kHz tick" at 1e+06, graph 0.97 right rotate by 90 offset -1.3,0 font 'Sans,8' tc rgb '#b00000'
set arrow from 250000, graph 0 to 250000, graph 1 nohead dt 3 lw 1.5 lc rgb '#b00000' back
set label "4 kHz tick" at 250000, graph 0.97 right rotate by 90 offset -1.3,0 font 'Sans,8' tc rgb '#b00000'
set arrow from graph 0, first 0.169996 to graph 1, first 0.169996 nohead dt 2 lc rgb '#999999' back
set label 'no error (exact)' at graph 0.99, first 0.169996 right offset 0,0.7 font 'Sans,8' tc rgb '#666666'
set label "1 (no settling)" at graph 0.214305, graph 0.732256 left font 'Sans,8' front noenhanced
set label "4 (no settling)" at graph 0.0256812, graph 0.75964 left font 'Sans,8' front noenhanced
set label "12 (default)" at graph 0.00865399, graph 0.735886 left font 'Sans,8' front noenhanced
set label "32 (no settling)" at graph 0.193036, graph 0.699053 left font 'Sans,8' front noenhanced
set label "0 (no settling)" at graph 0.0343262, graph 0.791344 left font 'Sans,8' front noenhanced
set label "2 (no settling)" at graph 0.217991, graph 0.777781 left font 'Sans,8' front noenhanced
set label "6 (default)" at graph 0.0185713, graph 0.69941 left font 'Sans,8' front noenhanced
set label "18 (no settling)" at graph 0.199528, graph 0.762367 left font 'Sans,8' front noenhanced
$dynamics_dynamic_0 << EOD
78670 0.169996
EOD
$dynamics_dynamic_1 << EOD
61727 5.25069
EOD
$dynamics_dynamic_2 << EOD
65836 5.09988
61438 6.04639
50634 5.21626
60294 5.2047
EOD
$dynamics_dynamic_3 << EOD
63240 6.51731
66847 6.76829
50634 5.21626
62359 5.44289
EOD
$dynamics_dynamic_front << EOD
50634 5.21626
60294 5.2047
65836 5.09988
78670 0.169996
EOD
plot $dynamics_dynamic_front using 1:2 with lines dt 2 lw 2 lc rgb '#888888' title 'Pareto front', \
  $dynamics_dynamic_0 using 1:2 with points pt 7 ps 1.6 lc rgb '#1f77b4' title "hapticd-tick iterations 100/50 (the truth)" noenhanced, \
  $dynamics_dynamic_1 using 1:2 with points pt 5 ps 1.6 lc rgb '#d62728' title "hapticd-tick no settling iterations (12/6 fixed)" noenhanced, \
  $dynamics_dynamic_2 using 1:2 with linespoints lw 1.5 pt 9 ps 1.6 lc rgb '#2ca02c' title "hapticd-tick, velocity iterations swept" noenhanced, \
  $dynamics_dynamic_3 using 1:2 with linespoints lw 1.5 pt 11 ps 1.6 lc rgb '#9467bd' title "hapticd-tick, split-impulse iterations swept" noenhanced
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
set xrange [85751.4:8.54043e+06]
set yrange [0.0365179:54.3477]
set xlabel 'p99.9 time per tick (ns)'
set ylabel 'p99 force error (N)'
set title "What accuracy costs in time: scene/stress" noenhanced
set key at screen 0.65, screen 0.91 left top Left reverse font 'Sans,9' spacing 1.2
set arrow from 1e+06, graph 0 to 1e+06, graph 1 nohead dt 3 lw 1.5 lc rgb '#b00000' back
set label "1 kHz tick" at 1e+06, graph 0.97 right rotate by 90 offset -1.3,0 font 'Sans,8' tc rgb '#b00000'
set arrow from 250000, graph 0 to 250000, graph 1 nohead dt 3 lw 1.5 lc rgb '#b00000' back
set label "4 kHz tick" at 250000, graph 0.97 right rotate by 90 offset -1.3,0 font 'Sans,8' tc rgb '#b00000'
set arrow from graph 0, first 0.11548 to graph 1, first 0.11548 nohead dt 2 lc rgb '#999999' back
set label 'no error (exact)' at graph 0.99, first 0.11548 right offset 0,0.7 font 'Sans,8' tc rgb '#666666'
set label "8" at graph 0.373596, graph 0.764417 left font 'Sans,8' front noenhanced
set label "4" at graph 0.338679, graph 0.70503 left font 'Sans,8' front noenhanced
set label "2" at graph 0.268944, graph 0.759709 left font 'Sans,8' front noenhanced
set label "1" at graph 0.185428, graph 0.721114 left font 'Sans,8' front noenhanced
set label "0.003" at graph 0.326769, graph 0.654277 left font 'Sans,8' front noenhanced
set label "0.01" at graph 0.338011, graph 0.676964 left font 'Sans,8' front noenhanced
set label "0.03" at graph 0.264078, graph 0.696057 left font 'Sans,8' front noenhanced
set label "2 kHz" at graph 0.340264, graph 0.741866 left font 'Sans,8' front noenhanced
set label "4 kHz" at graph 0.237124, graph 0.72187 left font 'Sans,8' front noenhanced
$scene_stress_0 << EOD
425077 0.11548
EOD
$scene_stress_1 << EOD
453581 9.72194
386263 6.29994
280243 9.39322
190832 7.08545
EOD
$scene_stress_2 << EOD
489841 6.91989
EOD
$scene_stress_3 << EOD
365666 4.34826
388017 5.92388
365865 5.90024
EOD
$scene_stress_4 << EOD
389089 8.24531
338282 7.1247
EOD
$scene_stress_5 << EOD
451948 13.6515
EOD
$scene_stress_6 << EOD
1.00224e+06 4.28113
EOD
$scene_stress_7 << EOD
4.80264e+06 7.10861
EOD
$scene_stress_8 << EOD
4.03461e+06 7.74468
EOD
$scene_stress_9 << EOD
152490 3.46439
EOD
$scene_stress_front << EOD
152490 3.46439
425077 0.11548
EOD
plot $scene_stress_front using 1:2 with lines dt 2 lw 2 lc rgb '#888888' title 'Pareto front', \
  $scene_stress_0 using 1:2 with points pt 7 ps 1.6 lc rgb '#1f77b4' title "hapticd-tick exact, budget unlimited, δ on (the truth)" noenhanced, \
  $scene_stress_1 using 1:2 with linespoints lw 1.5 pt 5 ps 1.6 lc rgb '#d62728' title "hapticd-tick, budget swept" noenhanced, \
  $scene_stress_2 using 1:2 with points pt 9 ps 1.6 lc rgb '#2ca02c' title "hapticd-tick δ off" noenhanced, \
  $scene_stress_3 using 1:2 with linespoints lw 1.5 pt 11 ps 1.6 lc rgb '#9467bd' title "hapticd-tick, tessellation swept" noenhanced, \
  $scene_stress_4 using 1:2 with linespoints lw 1.5 pt 13 ps 1.6 lc rgb '#ff7f0e' title "hapticd-tick, servo rate swept" noenhanced, \
  $scene_stress_5 using 1:2 with points pt 4 ps 1.6 lc rgb '#8c564b' title "hapticd-depth-along-motion closed loop" noenhanced, \
  $scene_stress_6 using 1:2 with points pt 6 ps 1.6 lc rgb '#e377c2' title "FCL-libccd closed loop" noenhanced, \
  $scene_stress_7 using 1:2 with points pt 8 ps 1.6 lc rgb '#17becf' title "Bullet-btGjkPairDetector closed loop" noenhanced, \
  $scene_stress_8 using 1:2 with points pt 10 ps 1.6 lc rgb '#7f7f7f' title "Bullet-btGjkEpaSolver2 closed loop" noenhanced, \
  $scene_stress_9 using 1:2 with points pt 12 ps 1.6 lc rgb '#bcbd22' title "voxel-McNeely, h swept" noenhanced
reset
set terminal pngcairo size 1100,660 font 'Sans,10'
set output "docs/accuracy/shaping_stress.png"
set lmargin at screen 0.08
set rmargin at screen 0.63
set bmargin at screen 0.1
set tmargin at screen 0.91
set logscale xy
set grid xtics ytics mxtics mytics lc rgb '#dddddd'
set format x '10^{%L}'
set format y '10^{%L}'
set xrange [140585:1.77828e+06]
set yrange [0.00520613:15.3874]
set xlabel 'p99.9 time per tick (ns)'
set ylabel 'p99 force error (N)'
set title "What accuracy costs in time: shaping/stress" noenhanced
set key at screen 0.65, screen 0.91 left top Left reverse font 'Sans,9' spacing 1.2
set arrow from 1e+06, graph 0 to 1e+06, graph 1 nohead dt 3 lw 1.5 lc rgb '#b00000' back
set label "1 kHz tick" at 1e+06, graph 0.97 right rotate by 90 offset -1.3,0 font 'Sans,8' tc rgb '#b00000'
set arrow from 250000, graph 0 to 250000, graph 1 nohead dt 3 lw 1.5 lc rgb '#b00000' back
set label "4 kHz tick" at 250000, graph 0.97 right rotate by 90 offset -1.3,0 font 'Sans,8' tc rgb '#b00000'
set arrow from graph 0, first 0.0164632 to graph 1, first 0.0164632 nohead dt 2 lc rgb '#999999' back
set label 'no error (exact)' at graph 0.99, first 0.0164632 right offset 0,0.7 font 'Sans,8' tc rgb '#666666'
set label "0.1 N/tick" at graph 0.452041, graph 0.827122 left font 'Sans,8' front noenhanced
set label "0.25 N/tick" at graph 0.45452, graph 0.803889 left font 'Sans,8' front noenhanced
set label "0.5 N/tick (default)" at graph 0.480496, graph 0.63889 left font 'Sans,8' front noenhanced
set label "2 N/tick" at graph 0.41056, graph 0.167447 left font 'Sans,8' front noenhanced
set label "0° (shading off)" at graph 0.424573, graph 0.569669 left font 'Sans,8' front noenhanced
set label "20°" at graph 0.37909, graph 0.144065 left font 'Sans,8' front noenhanced
set label "60°" at graph 0.427989, graph 0.120683 left font 'Sans,8' front noenhanced
set label "85°" at graph 0.388283, graph 0.107589 left font 'Sans,8' front noenhanced
$shaping_stress_0 << EOD
445688 0.0164632
EOD
$shaping_stress_1 << EOD
429898 3.86515
432611 3.2102
462088 0.858772
440676 0.0164632
EOD
$shaping_stress_2 << EOD
400953 0.493897
418976 0.0164632
437994 0.0164632
428865 0.0164632
EOD
$shaping_stress_front << EOD
400953 0.493897
418976 0.0164632
EOD
plot $shaping_stress_front using 1:2 with lines dt 2 lw 2 lc rgb '#888888' title 'Pareto front', \
  $shaping_stress_0 using 1:2 with points pt 7 ps 1.6 lc rgb '#1f77b4' title "hapticd-tick no step limit, shading 40° (the truth)" noenhanced, \
  $shaping_stress_1 using 1:2 with linespoints lw 1.5 pt 5 ps 1.6 lc rgb '#d62728' title "hapticd-tick, F_max swept" noenhanced, \
  $shaping_stress_2 using 1:2 with linespoints lw 1.5 pt 9 ps 1.6 lc rgb '#2ca02c' title "hapticd-tick, crease angle swept" noenhanced
reset
set terminal pngcairo size 1100,660 font 'Sans,10'
set output "docs/accuracy/dynamics_stack.png"
set lmargin at screen 0.08
set rmargin at screen 0.63
set bmargin at screen 0.1
set tmargin at screen 0.91
set logscale xy
set grid xtics ytics mxtics mytics lc rgb '#dddddd'
set format x '10^{%L}'
set format y '10^{%L}'
set xrange [48205.6:1.77828e+06]
set yrange [0.00093633:0.881177]
set xlabel 'p99.9 time per tick (ns)'
set ylabel 'p99 force error (N)'
set title "What accuracy costs in time: dynamics/stack" noenhanced
set key at screen 0.65, screen 0.91 left top Left reverse font 'Sans,9' spacing 1.2
set arrow from 1e+06, graph 0 to 1e+06, graph 1 nohead dt 3 lw 1.5 lc rgb '#b00000' back
set label "1 kHz tick" at 1e+06, graph 0.97 right rotate by 90 offset -1.3,0 font 'Sans,8' tc rgb '#b00000'
set arrow from 250000, graph 0 to 250000, graph 1 nohead dt 3 lw 1.5 lc rgb '#b00000' back
set label "4 kHz tick" at 250000, graph 0.97 right rotate by 90 offset -1.3,0 font 'Sans,8' tc rgb '#b00000'
set arrow from graph 0, first 0.00296094 to graph 1, first 0.00296094 nohead dt 2 lc rgb '#999999' back
set label 'no error (exact)' at graph 0.99, first 0.00296094 right offset 0,0.7 font 'Sans,8' tc rgb '#666666'
set label "1 (no settling)" at graph 0.148464, graph 0.821609 left font 'Sans,8' front noenhanced
set label "4 (no settling)" at graph 0.121832, graph 0.773898 left font 'Sans,8' front noenhanced
set label "12 (default)" at graph 0.256533, graph 0.709955 left font 'Sans,8' front noenhanced
set label "32 (no settling)" at graph 0.280554, graph 0.664884 left font 'Sans,8' front noenhanced
set label "0 (no settling)" at graph 0.248833, graph 0.797137 left font 'Sans,8' front noenhanced
set label "2 (no settling)" at graph 0.000872751, graph 0.816778 left font 'Sans,8' front noenhanced
set label "6 (default)" at graph 0.124301, graph 0.709955 left font 'Sans,8' front noenhanced
set label "18 (no settling)" at graph 0.254333, graph 0.760661 left font 'Sans,8' front noenhanced
$dynamics_stack_0 << EOD
192817 0.00296094
EOD
$dynamics_stack_1 << EOD
110781 0.219696
EOD
$dynamics_stack_2 << EOD
107714 0.221342
97846 0.219912
116662 0.120942
127224 0.0888281
EOD
$dynamics_stack_3 << EOD
113466 0.219696
85723 0.219696
116662 0.120942
115740 0.219696
EOD
$dynamics_stack_front << EOD
85723 0.219696
116662 0.120942
127224 0.0888281
192817 0.00296094
EOD
plot $dynamics_stack_front using 1:2 with lines dt 2 lw 2 lc rgb '#888888' title 'Pareto front', \
  $dynamics_stack_0 using 1:2 with points pt 7 ps 1.6 lc rgb '#1f77b4' title "hapticd-tick iterations 100/50 (the truth)" noenhanced, \
  $dynamics_stack_1 using 1:2 with points pt 5 ps 1.6 lc rgb '#d62728' title "hapticd-tick no settling iterations (12/6 fixed)" noenhanced, \
  $dynamics_stack_2 using 1:2 with linespoints lw 1.5 pt 9 ps 1.6 lc rgb '#2ca02c' title "hapticd-tick, velocity iterations swept" noenhanced, \
  $dynamics_stack_3 using 1:2 with linespoints lw 1.5 pt 11 ps 1.6 lc rgb '#9467bd' title "hapticd-tick, split-impulse iterations swept" noenhanced
reset
set terminal pngcairo size 1100,660 font 'Sans,10'
set output "docs/accuracy/decomposition_crescent.png"
set lmargin at screen 0.08
set rmargin at screen 0.63
set bmargin at screen 0.1
set tmargin at screen 0.91
set logscale xy
set grid xtics ytics mxtics mytics lc rgb '#dddddd'
set format x '10^{%L}'
set format y '10^{%L}'
set xrange [2399.51:1.77828e+06]
set yrange [0.00169535:8.08252]
set xlabel 'median time per query (ns)'
set ylabel 'p99 force error (N)'
set title "What accuracy costs in time: decomposition/crescent" noenhanced
set key at screen 0.65, screen 0.91 left top Left reverse font 'Sans,9' spacing 1.2
set arrow from 1e+06, graph 0 to 1e+06, graph 1 nohead dt 3 lw 1.5 lc rgb '#b00000' back
set label "1 kHz tick" at 1e+06, graph 0.97 right rotate by 90 offset -1.3,0 font 'Sans,8' tc rgb '#b00000'
set arrow from 250000, graph 0 to 250000, graph 1 nohead dt 3 lw 1.5 lc rgb '#b00000' back
set label "4 kHz tick" at 250000, graph 0.97 right rotate by 90 offset -1.3,0 font 'Sans,8' tc rgb '#b00000'
set arrow from graph 0, first 0.00536117 to graph 1, first 0.00536117 nohead dt 2 lc rgb '#999999' back
set label 'no error (exact)' at graph 0.99, first 0.00536117 right offset 0,0.7 font 'Sans,8' tc rgb '#666666'
set label "0.08" at graph 0.098682, graph 0.836881 left font 'Sans,8' front noenhanced
set label "0.04" at graph 0.0954162, graph 0.793172 left font 'Sans,8' front noenhanced
set label "0.02" at graph 0.143822, graph 0.689265 left font 'Sans,8' front noenhanced
set label "0.01 (default)" at graph 0.196905, graph 0.65387 left font 'Sans,8' front noenhanced
set label "0.005" at graph 0.198563, graph 0.537511 left font 'Sans,8' front noenhanced
$decomposition_crescent_0 << EOD
10601 0.00536117
EOD
$decomposition_crescent_1 << EOD
4267 2.03024
5139 1.70915
5750 0.581535
8166 0.430905
8256 0.160835
EOD
$decomposition_crescent_front << EOD
4267 2.03024
5139 1.70915
5750 0.581535
8166 0.430905
8256 0.160835
10601 0.00536117
EOD
plot $decomposition_crescent_front using 1:2 with lines dt 2 lw 2 lc rgb '#888888' title 'Pareto front', \
  $decomposition_crescent_0 using 1:2 with points pt 7 ps 1.6 lc rgb '#1f77b4' title "exact mesh brute force (the truth)" noenhanced, \
  $decomposition_crescent_1 using 1:2 with linespoints lw 1.5 pt 5 ps 1.6 lc rgb '#d62728' title "decomposition, concavity swept" noenhanced
reset
set terminal pngcairo size 1100,660 font 'Sans,10'
set output "docs/accuracy/decomposition_crescent-tick.png"
set lmargin at screen 0.08
set rmargin at screen 0.63
set bmargin at screen 0.1
set tmargin at screen 0.91
set logscale xy
set grid xtics ytics mxtics mytics lc rgb '#dddddd'
set format x '10^{%L}'
set format y '10^{%L}'
set xrange [27849.4:1.77828e+06]
set yrange [0.000898423:7.87693]
set xlabel 'p99.9 time per tick (ns)'
set ylabel 'p99 force error (N)'
set title "What accuracy costs in time: decomposition/crescent-tick" noenhanced
set key at screen 0.65, screen 0.91 left top Left reverse font 'Sans,9' spacing 1.2
set arrow from 1e+06, graph 0 to 1e+06, graph 1 nohead dt 3 lw 1.5 lc rgb '#b00000' back
set label "1 kHz tick" at 1e+06, graph 0.97 right rotate by 90 offset -1.3,0 font 'Sans,8' tc rgb '#b00000'
set arrow from 250000, graph 0 to 250000, graph 1 nohead dt 3 lw 1.5 lc rgb '#b00000' back
set label "4 kHz tick" at 250000, graph 0.97 right rotate by 90 offset -1.3,0 font 'Sans,8' tc rgb '#b00000'
set arrow from graph 0, first 0.00284106 to graph 1, first 0.00284106 nohead dt 2 lc rgb '#999999' back
set label 'no error (exact)' at graph 0.99, first 0.00284106 right offset 0,0.7 font 'Sans,8' tc rgb '#666666'
set label "0.08" at graph 0.163453, graph 0.847827 left font 'Sans,8' front noenhanced
set label "0.04" at graph 0.152097, graph 0.821512 left font 'Sans,8' front noenhanced
set label "0.02" at graph 0.15006, graph 0.705893 left font 'Sans,8' front noenhanced
set label "0.01 (default)" at graph 0.152338, graph 0.671165 left font 'Sans,8' front noenhanced
set label "0.005" at graph 0.15301, graph 0.501441 left font 'Sans,8' front noenhanced
$decomposition_crescent_tick_0 << EOD
97266 0.00284106
EOD
$decomposition_crescent_tick_1 << EOD
52359 1.9786
49945 1.55812
49524 0.54542
49995 0.397924
50135 0.0852319
EOD
$decomposition_crescent_tick_front << EOD
49524 0.54542
49995 0.397924
50135 0.0852319
97266 0.00284106
EOD
plot $decomposition_crescent_tick_front using 1:2 with lines dt 2 lw 2 lc rgb '#888888' title 'Pareto front', \
  $decomposition_crescent_tick_0 using 1:2 with points pt 7 ps 1.6 lc rgb '#1f77b4' title "exact mesh pairs answered from it (the truth)" noenhanced, \
  $decomposition_crescent_tick_1 using 1:2 with linespoints lw 1.5 pt 5 ps 1.6 lc rgb '#d62728' title "hapticd-tick, concavity swept" noenhanced
