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
set label "2mm" at graph 0.26118, graph 0.912978 left font 'Sans,8' front noenhanced
set label "1mm" at graph 0.439521, graph 0.912643 left font 'Sans,8' front noenhanced
set label "0.5mm" at graph 0.567024, graph 0.913303 left font 'Sans,8' front noenhanced
set label "0.25mm" at graph 0.698652, graph 0.915836 left font 'Sans,8' front noenhanced
$pairs_8_0 << EOD
932 1.67388e-16
EOD
$pairs_8_1 << EOD
1122 1.67388e-16
EOD
$pairs_8_2 << EOD
100 15.1584
EOD
$pairs_8_3 << EOD
1051 0.037277
EOD
$pairs_8_4 << EOD
470 0.976496
EOD
$pairs_8_5 << EOD
1603 0.976496
EOD
$pairs_8_6 << EOD
2064 5.02164e-15
EOD
$pairs_8_7 << EOD
1554 5.49364e-15
EOD
$pairs_8_8 << EOD
1292 1.61924
4740 1.5968
17764 1.64122
69481 1.8235
EOD
$pairs_8_front << EOD
100 15.1584
470 0.976496
932 1.67388e-16
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
set xrange [106.845:1.77828e+06]
set yrange [6.29794e-17:75.9909]
set xlabel 'median time per query (ns)'
set ylabel 'p99 force error (N)'
set title "What accuracy costs in time: pairs/32" noenhanced
set key at screen 0.65, screen 0.91 left top Left reverse font 'Sans,9' spacing 1.2
set arrow from 1e+06, graph 0 to 1e+06, graph 1 nohead dt 3 lw 1.5 lc rgb '#b00000' back
set label "1 kHz tick" at 1e+06, graph 0.97 right rotate by 90 offset -1.3,0 font 'Sans,8' tc rgb '#b00000'
set arrow from 250000, graph 0 to 250000, graph 1 nohead dt 3 lw 1.5 lc rgb '#b00000' back
set label "4 kHz tick" at 250000, graph 0.97 right rotate by 90 offset -1.3,0 font 'Sans,8' tc rgb '#b00000'
set label "2mm" at graph 0.364396, graph 0.903153 left font 'Sans,8' front noenhanced
set label "1mm" at graph 0.501543, graph 0.906912 left font 'Sans,8' front noenhanced
set label "0.5mm" at graph 0.63862, graph 0.90828 left font 'Sans,8' front noenhanced
set label "0.25mm" at graph 0.697864, graph 0.90844 left font 'Sans,8' front noenhanced
$pairs_32_0 << EOD
1653 5.97475e-15
EOD
$pairs_32_1 << EOD
1473 5.97475e-15
EOD
$pairs_32_2 << EOD
190 19.0881
EOD
$pairs_32_3 << EOD
1893 0.0373738
EOD
$pairs_32_4 << EOD
961 0.355001
EOD
$pairs_32_5 << EOD
2665 0.324079
EOD
$pairs_32_6 << EOD
3557 8.90573e-15
EOD
$pairs_32_7 << EOD
2665 9.62266e-15
EOD
$pairs_32_8 << EOD
3297 1.34775
12504 1.57608
47390 1.66848
188205 1.67964
EOD
$pairs_32_front << EOD
190 19.0881
961 0.355001
1473 5.97475e-15
1653 5.97475e-15
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
set xrange [225.499:1.77828e+06]
set yrange [6.37184e-17:77.7992]
set xlabel 'median time per query (ns)'
set ylabel 'p99 force error (N)'
set title "What accuracy costs in time: pairs/128" noenhanced
set key at screen 0.65, screen 0.91 left top Left reverse font 'Sans,9' spacing 1.2
set arrow from 1e+06, graph 0 to 1e+06, graph 1 nohead dt 3 lw 1.5 lc rgb '#b00000' back
set label "1 kHz tick" at 1e+06, graph 0.97 right rotate by 90 offset -1.3,0 font 'Sans,8' tc rgb '#b00000'
set arrow from 250000, graph 0 to 250000, graph 1 nohead dt 3 lw 1.5 lc rgb '#b00000' back
set label "4 kHz tick" at 250000, graph 0.97 right rotate by 90 offset -1.3,0 font 'Sans,8' tc rgb '#b00000'
set label "2mm" at graph 0.339812, graph 0.895944 left font 'Sans,8' front noenhanced
set label "1mm" at graph 0.481416, graph 0.899083 left font 'Sans,8' front noenhanced
set label "0.5mm" at graph 0.628733, graph 0.902287 left font 'Sans,8' front noenhanced
set label "0.25mm" at graph 0.69792, graph 0.903916 left font 'Sans,8' front noenhanced
$pairs_128_0 << EOD
2755 6.14985e-15
EOD
$pairs_128_1 << EOD
2455 6.04486e-15
EOD
$pairs_128_2 << EOD
401 19.5423
EOD
$pairs_128_3 << EOD
5160 0.0339337
EOD
$pairs_128_4 << EOD
3336 0.540271
EOD
$pairs_128_5 << EOD
3166 0.570367
EOD
$pairs_128_6 << EOD
8937 0.00433206
EOD
$pairs_128_7 << EOD
6472 1.38057e-14
EOD
$pairs_128_8 << EOD
4288 1.02081
15278 1.16336
57298 1.32942
223772 1.42276
EOD
$pairs_128_front << EOD
401 19.5423
2455 6.04486e-15
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
set xrange [11561.2:1.77828e+06]
set yrange [5.13112e-05:46.5641]
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
set label "8" at graph 0.155122, graph 0.107305 left font 'Sans,8' front noenhanced
set label "4" at graph 0.1542, graph 0.0605411 left font 'Sans,8' front noenhanced
set label "2" at graph 0.121927, graph 0.083923 left font 'Sans,8' front noenhanced
set label "1" at graph 0.177473, graph 0.103564 left font 'Sans,8' front noenhanced
set label "2 kHz" at graph 0.165093, graph 0.331852 left font 'Sans,8' front noenhanced
set label "4 kHz" at graph 0.167222, graph 0.393407 left font 'Sans,8' front noenhanced
set label "3.32mm" at graph 0.125882, graph 0.872067 left font 'Sans,8' front noenhanced
set label "1.66mm" at graph 0.165588, graph 0.912579 left font 'Sans,8' front noenhanced
set label "0.829mm" at graph 0.373517, graph 0.882559 left font 'Sans,8' front noenhanced
$scene_peg_in_hole_0 << EOD
26891 0.00016226
EOD
$scene_peg_in_hole_1 << EOD
25888 0.00016226
25768 0.00016226
23804 0.00016226
26881 0.00016226
EOD
$scene_peg_in_hole_2 << EOD
25038 0.026241
EOD
$scene_peg_in_hole_3 << EOD
25047 0.00486781
25317 0.0113258
EOD
$scene_peg_in_hole_4 << EOD
43151 11.6964
EOD
$scene_peg_in_hole_5 << EOD
33423 0.00016226
EOD
$scene_peg_in_hole_6 << EOD
31971 0.00016226
EOD
$scene_peg_in_hole_7 << EOD
28123 0.00016226
EOD
$scene_peg_in_hole_8 << EOD
20559 8.05094
30918 10.1836
71545 9.29728
EOD
$scene_peg_in_hole_front << EOD
20559 8.05094
23804 0.00016226
25768 0.00016226
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
set xrange [13623.3:1.77828e+06]
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
set label "0.1 N/tick" at graph 0.0103638, graph 0.194015 left font 'Sans,8' front noenhanced
set label "0.25 N/tick" at graph 0.0747732, graph 0.217397 left font 'Sans,8' front noenhanced
set label "0.5 N/tick (default)" at graph 0.0189896, graph 0.170633 left font 'Sans,8' front noenhanced
set label "2 N/tick" at graph 0.1424, graph 0.194015 left font 'Sans,8' front noenhanced
set label "0° (shading off)" at graph 0.140085, graph 0.230491 left font 'Sans,8' front noenhanced
set label "20°" at graph 0.174338, graph 0.157539 left font 'Sans,8' front noenhanced
set label "60°" at graph 0.080932, graph 0.230491 left font 'Sans,8' front noenhanced
set label "85°" at graph 0.078632, graph 0.157539 left font 'Sans,8' front noenhanced
$shaping_peg_in_hole_0 << EOD
24617 0.0333333
EOD
$shaping_peg_in_hole_1 << EOD
24576 0.0333333
25579 0.0333333
24226 0.0333333
25768 0.0333333
EOD
$shaping_peg_in_hole_2 << EOD
25479 0.0333333
30106 0.0333333
25937 0.0333333
25648 0.0333333
EOD
$shaping_peg_in_hole_front << EOD
24226 0.0333333
24617 0.0333333
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
set xrange [25100.1:1.77828e+06]
set yrange [3.0683e-05:0.168927]
set xlabel 'p99.9 time per tick (ns)'
set ylabel 'p99 force error (N)'
set title "What accuracy costs in time: scene/gears" noenhanced
set key at screen 0.65, screen 0.91 left top Left reverse font 'Sans,9' spacing 1.2
set arrow from 1e+06, graph 0 to 1e+06, graph 1 nohead dt 3 lw 1.5 lc rgb '#b00000' back
set label "1 kHz tick" at 1e+06, graph 0.97 right rotate by 90 offset -1.3,0 font 'Sans,8' tc rgb '#b00000'
set arrow from 250000, graph 0 to 250000, graph 1 nohead dt 3 lw 1.5 lc rgb '#b00000' back
set label "4 kHz tick" at 250000, graph 0.97 right rotate by 90 offset -1.3,0 font 'Sans,8' tc rgb '#b00000'
set arrow from graph 0, first 9.70282e-05 to graph 1, first 9.70282e-05 nohead dt 2 lc rgb '#999999' back
set label 'no error (exact)' at graph 0.99, first 9.70282e-05 right offset 0,0.7 font 'Sans,8' tc rgb '#666666'
set label "8" at graph 0.160634, graph 0.133661 left font 'Sans,8' front noenhanced
set label "4" at graph 0.160505, graph 0.569357 left font 'Sans,8' front noenhanced
set label "2" at graph 0.113624, graph 0.581434 left font 'Sans,8' front noenhanced
set label "1" at graph 0.136436, graph 0.605569 left font 'Sans,8' front noenhanced
set label "2 kHz" at graph 0.235307, graph 0.528529 left font 'Sans,8' front noenhanced
set label "4 kHz" at graph 0.217807, graph 0.560637 left font 'Sans,8' front noenhanced
$scene_gears_0 << EOD
59852 9.70282e-05
EOD
$scene_gears_1 << EOD
54533 9.70282e-05
54503 0.00413759
44635 0.00459122
45846 0.00462107
EOD
$scene_gears_2 << EOD
56027 9.70282e-05
EOD
$scene_gears_3 << EOD
65112 0.00291085
60434 0.00383823
EOD
$scene_gears_4 << EOD
75072 0.0424326
EOD
$scene_gears_5 << EOD
95530 0.0110428
EOD
$scene_gears_6 << EOD
99768 0.00830454
EOD
$scene_gears_7 << EOD
77737 0.00700686
EOD
$scene_gears_front << EOD
44635 0.00459122
54503 0.00413759
54533 9.70282e-05
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
set xrange [28891.4:1.77828e+06]
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
set label "0.1 N/tick" at graph 0.0297828, graph 0.194015 left font 'Sans,8' front noenhanced
set label "0.25 N/tick" at graph 0.0871134, graph 0.217397 left font 'Sans,8' front noenhanced
set label "0.5 N/tick (default)" at graph 0.0405513, graph 0.170633 left font 'Sans,8' front noenhanced
set label "2 N/tick" at graph 0.187791, graph 0.194015 left font 'Sans,8' front noenhanced
set label "0° (shading off)" at graph 0.173962, graph 0.230491 left font 'Sans,8' front noenhanced
set label "20°" at graph 0.163386, graph 0.157539 left font 'Sans,8' front noenhanced
set label "60°" at graph 0.106403, graph 0.230491 left font 'Sans,8' front noenhanced
set label "85°" at graph 0.095158, graph 0.157539 left font 'Sans,8' front noenhanced
$shaping_gears_0 << EOD
57168 0.0333333
EOD
$shaping_gears_1 << EOD
51547 0.0333333
51788 0.0333333
51377 0.0333333
59713 0.0333333
EOD
$shaping_gears_2 << EOD
56406 0.0333333
54001 0.0333333
55313 0.0333333
52809 0.0333333
EOD
$shaping_gears_front << EOD
51377 0.0333333
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
set xrange [10822.8:1.77828e+06]
set yrange [6.31029e-06:39.8107]
set xlabel 'p99.9 time per tick (ns)'
set ylabel 'p99 force error (N)'
set title "What accuracy costs in time: scene/dynamic" noenhanced
set key at screen 0.65, screen 0.91 left top Left reverse font 'Sans,9' spacing 1.2
set arrow from 1e+06, graph 0 to 1e+06, graph 1 nohead dt 3 lw 1.5 lc rgb '#b00000' back
set label "1 kHz tick" at 1e+06, graph 0.97 right rotate by 90 offset -1.3,0 font 'Sans,8' tc rgb '#b00000'
set arrow from 250000, graph 0 to 250000, graph 1 nohead dt 3 lw 1.5 lc rgb '#b00000' back
set label "4 kHz tick" at 250000, graph 0.97 right rotate by 90 offset -1.3,0 font 'Sans,8' tc rgb '#b00000'
set arrow from graph 0, first 1.99549e-05 to graph 1, first 1.99549e-05 nohead dt 2 lc rgb '#999999' back
set label 'no error (exact)' at graph 0.99, first 1.99549e-05 right offset 0,0.7 font 'Sans,8' tc rgb '#666666'
set label "8" at graph 0.240143, graph 0.290755 left font 'Sans,8' front noenhanced
set label "4" at graph 0.260019, graph 0.624445 left font 'Sans,8' front noenhanced
set label "2" at graph 0.263706, graph 0.483738 left font 'Sans,8' front noenhanced
set label "1" at graph 0.32046, graph 0.911764 left font 'Sans,8' front noenhanced
set label "2 kHz" at graph 0.159446, graph 0.822103 left font 'Sans,8' front noenhanced
set label "4 kHz" at graph 0.242616, graph 0.813247 left font 'Sans,8' front noenhanced
set label "7.63mm" at graph 0.0417588, graph 0.56134 left font 'Sans,8' front noenhanced
set label "3.82mm" at graph 0.152233, graph 0.56134 left font 'Sans,8' front noenhanced
set label "1.91mm" at graph 0.258473, graph 0.56134 left font 'Sans,8' front noenhanced
$scene_dynamic_0 << EOD
36269 1.99549e-05
EOD
$scene_dynamic_1 << EOD
34736 0.000598647
38443 0.111235
39173 0.0122869
52328 10
EOD
$scene_dynamic_2 << EOD
37291 0.323968
EOD
$scene_dynamic_3 << EOD
33352 2.45645
35177 2.13841
EOD
$scene_dynamic_4 << EOD
90742 10
EOD
$scene_dynamic_5 << EOD
76333 4.6067
EOD
$scene_dynamic_6 << EOD
81233 1.05185
EOD
$scene_dynamic_7 << EOD
60844 1.01392
EOD
$scene_dynamic_8 << EOD
19246 0.0414129
22182 0.0414129
38141 0.0414129
EOD
$scene_dynamic_front << EOD
19246 0.0414129
34736 0.000598647
36269 1.99549e-05
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
set xrange [18046.1:1.77828e+06]
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
set label "1" at graph 0.192498, graph 0.732256 left font 'Sans,8' front noenhanced
set label "4" at graph 0.103913, graph 0.75964 left font 'Sans,8' front noenhanced
set label "12 (default)" at graph 0.0126388, graph 0.736944 left font 'Sans,8' front noenhanced
set label "32" at graph 0.1568, graph 0.712147 left font 'Sans,8' front noenhanced
set label "0" at graph 0.163271, graph 0.771703 left font 'Sans,8' front noenhanced
set label "2" at graph 0.133126, graph 0.801163 left font 'Sans,8' front noenhanced
set label "6 (default)" at graph 0.0225561, graph 0.700468 left font 'Sans,8' front noenhanced
set label "18" at graph 0.160103, graph 0.762367 left font 'Sans,8' front noenhanced
$dynamics_dynamic_0 << EOD
53632 0.169996
EOD
$dynamics_dynamic_1 << EOD
41408 5.09988
32091 6.04639
34826 5.25069
38793 5.2047
EOD
$dynamics_dynamic_2 << EOD
36209 6.51731
34015 6.76829
34826 5.25069
35958 5.44289
EOD
$dynamics_dynamic_front << EOD
32091 6.04639
34826 5.25069
38793 5.2047
41408 5.09988
53632 0.169996
EOD
plot $dynamics_dynamic_front using 1:2 with lines dt 2 lw 2 lc rgb '#888888' title 'Pareto front', \
  $dynamics_dynamic_0 using 1:2 with points pt 7 ps 1.6 lc rgb '#1f77b4' title "hapticd-tick iterations 100/50 (the truth)" noenhanced, \
  $dynamics_dynamic_1 using 1:2 with linespoints lw 1.5 pt 5 ps 1.6 lc rgb '#d62728' title "hapticd-tick, velocity iterations swept" noenhanced, \
  $dynamics_dynamic_2 using 1:2 with linespoints lw 1.5 pt 9 ps 1.6 lc rgb '#2ca02c' title "hapticd-tick, split-impulse iterations swept" noenhanced
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
set xrange [47274.9:6.24659e+06]
set yrange [0.0232081:39.8861]
set xlabel 'p99.9 time per tick (ns)'
set ylabel 'p99 force error (N)'
set title "What accuracy costs in time: scene/stress" noenhanced
set key at screen 0.65, screen 0.91 left top Left reverse font 'Sans,9' spacing 1.2
set arrow from 1e+06, graph 0 to 1e+06, graph 1 nohead dt 3 lw 1.5 lc rgb '#b00000' back
set label "1 kHz tick" at 1e+06, graph 0.97 right rotate by 90 offset -1.3,0 font 'Sans,8' tc rgb '#b00000'
set arrow from 250000, graph 0 to 250000, graph 1 nohead dt 3 lw 1.5 lc rgb '#b00000' back
set label "4 kHz tick" at 250000, graph 0.97 right rotate by 90 offset -1.3,0 font 'Sans,8' tc rgb '#b00000'
set arrow from graph 0, first 0.0733904 to graph 1, first 0.0733904 nohead dt 2 lc rgb '#999999' back
set label 'no error (exact)' at graph 0.99, first 0.0733904 right offset 0,0.7 font 'Sans,8' tc rgb '#666666'
set label "8" at graph 0.307589, graph 0.734186 left font 'Sans,8' front noenhanced
set label "4" at graph 0.322704, graph 0.671455 left font 'Sans,8' front noenhanced
set label "2" at graph 0.22389, graph 0.710905 left font 'Sans,8' front noenhanced
set label "1" at graph 0.171296, graph 0.711133 left font 'Sans,8' front noenhanced
set label "0.003" at graph 0.255134, graph 0.611131 left font 'Sans,8' front noenhanced
set label "0.01" at graph 0.275371, graph 0.64569 left font 'Sans,8' front noenhanced
set label "0.03" at graph 0.344967, graph 0.780787 left font 'Sans,8' front noenhanced
set label "2 kHz" at graph 0.256398, graph 0.732459 left font 'Sans,8' front noenhanced
set label "4 kHz" at graph 0.239626, graph 0.68242 left font 'Sans,8' front noenhanced
$scene_stress_0 << EOD
248488 0.0733904
EOD
$scene_stress_1 << EOD
235834 5.50635
216047 3.45079
133341 4.62965
103136 4.63752
EOD
$scene_stress_2 << EOD
310776 3.68725
EOD
$scene_stress_3 << EOD
221558 2.20171
233011 2.84817
240863 7.79162
EOD
$scene_stress_4 << EOD
222930 4.1426
205397 3.74449
EOD
$scene_stress_5 << EOD
437345 10.0189
EOD
$scene_stress_6 << EOD
649975 6.20385
EOD
$scene_stress_7 << EOD
3.51271e+06 7.89814
EOD
$scene_stress_8 << EOD
2.70204e+06 8.02034
EOD
$scene_stress_9 << EOD
84068 3.049
EOD
$scene_stress_front << EOD
84068 3.049
221558 2.20171
248488 0.0733904
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
set xrange [137133:1.77828e+06]
set yrange [2.2981e-12:10.7748]
set xlabel 'p99.9 time per tick (ns)'
set ylabel 'p99 force error (N)'
set title "What accuracy costs in time: shaping/stress" noenhanced
set key at screen 0.65, screen 0.91 left top Left reverse font 'Sans,9' spacing 1.2
set arrow from 1e+06, graph 0 to 1e+06, graph 1 nohead dt 3 lw 1.5 lc rgb '#b00000' back
set label "1 kHz tick" at 1e+06, graph 0.97 right rotate by 90 offset -1.3,0 font 'Sans,8' tc rgb '#b00000'
set arrow from 250000, graph 0 to 250000, graph 1 nohead dt 3 lw 1.5 lc rgb '#b00000' back
set label "4 kHz tick" at 250000, graph 0.97 right rotate by 90 offset -1.3,0 font 'Sans,8' tc rgb '#b00000'
set arrow from graph 0, first 7.26724e-12 to graph 1, first 7.26724e-12 nohead dt 2 lc rgb '#999999' back
set label 'no error (exact)' at graph 0.99, first 7.26724e-12 right offset 0,0.7 font 'Sans,8' tc rgb '#666666'
set label "0.1 N/tick" at graph 0.238931, graph 0.972289 left font 'Sans,8' front noenhanced
set label "0.25 N/tick" at graph 0.247529, graph 0.940777 left font 'Sans,8' front noenhanced
set label "0.5 N/tick (default)" at graph 0.0165815, graph 0.0394601 left font 'Sans,8' front noenhanced
set label "2 N/tick" at graph 0.246095, graph 0.0394601 left font 'Sans,8' front noenhanced
set label "0° (shading off)" at graph 0.246517, graph 0.156035 left font 'Sans,8' front noenhanced
set label "20°" at graph 0.240153, graph 0.0759359 left font 'Sans,8' front noenhanced
set label "60°" at graph 0.175803, graph 0.0759359 left font 'Sans,8' front noenhanced
set label "85°" at graph 0.175652, graph 0.0198192 left font 'Sans,8' front noenhanced
$shaping_stress_0 << EOD
243861 7.26724e-12
EOD
$shaping_stress_1 << EOD
246605 2.7065
251033 1.91422
245021 7.26724e-12
250112 7.26724e-12
EOD
$shaping_stress_2 << EOD
250383 2.18017e-10
246333 7.26724e-12
245363 7.26724e-12
244231 7.26724e-12
EOD
$shaping_stress_front << EOD
243861 7.26724e-12
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
set xrange [20237.5:1.77828e+06]
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
set label "1" at graph 0.141537, graph 0.798227 left font 'Sans,8' front noenhanced
set label "4" at graph 0.107124, graph 0.79728 left font 'Sans,8' front noenhanced
set label "12 (default)" at graph 0.115302, graph 0.820519 left font 'Sans,8' front noenhanced
set label "32" at graph 0.25185, graph 0.664884 left font 'Sans,8' front noenhanced
set label "0" at graph 0.198525, graph 0.773755 left font 'Sans,8' front noenhanced
set label "2" at graph 0.156614, graph 0.773755 left font 'Sans,8' front noenhanced
set label "6 (default)" at graph 0.0541446, graph 0.760661 left font 'Sans,8' front noenhanced
set label "18" at graph 0.235529, graph 0.797137 left font 'Sans,8' front noenhanced
$dynamics_stack_0 << EOD
115668 0.00296094
EOD
$dynamics_stack_1 << EOD
36207 0.221342
35988 0.219912
44254 0.219696
59323 0.0888281
EOD
$dynamics_stack_2 << EOD
50315 0.219696
41709 0.219696
44254 0.219696
55144 0.219696
EOD
$dynamics_stack_front << EOD
35988 0.219912
41709 0.219696
59323 0.0888281
115668 0.00296094
EOD
plot $dynamics_stack_front using 1:2 with lines dt 2 lw 2 lc rgb '#888888' title 'Pareto front', \
  $dynamics_stack_0 using 1:2 with points pt 7 ps 1.6 lc rgb '#1f77b4' title "hapticd-tick iterations 100/50 (the truth)" noenhanced, \
  $dynamics_stack_1 using 1:2 with linespoints lw 1.5 pt 5 ps 1.6 lc rgb '#d62728' title "hapticd-tick, velocity iterations swept" noenhanced, \
  $dynamics_stack_2 using 1:2 with linespoints lw 1.5 pt 9 ps 1.6 lc rgb '#2ca02c' title "hapticd-tick, split-impulse iterations swept" noenhanced
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
set xrange [1780.37:1.77828e+06]
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
set label "0.08" at graph 0.0949178, graph 0.836881 left font 'Sans,8' front noenhanced
set label "0.04" at graph 0.101543, graph 0.793172 left font 'Sans,8' front noenhanced
set label "0.02" at graph 0.144794, graph 0.689265 left font 'Sans,8' front noenhanced
set label "0.01 (default)" at graph 0.19482, graph 0.65387 left font 'Sans,8' front noenhanced
set label "0.005" at graph 0.197996, graph 0.537511 left font 'Sans,8' front noenhanced
$decomposition_crescent_0 << EOD
6753 0.00536117
EOD
$decomposition_crescent_1 << EOD
3166 2.03024
4117 1.70915
4468 0.581535
6312 0.430905
6452 0.160835
EOD
$decomposition_crescent_front << EOD
3166 2.03024
4117 1.70915
4468 0.581535
6312 0.430905
6452 0.160835
6753 0.00536117
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
set xrange [13385.4:1.77828e+06]
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
set label "0.08" at graph 0.133921, graph 0.847827 left font 'Sans,8' front noenhanced
set label "0.04" at graph 0.13291, graph 0.821512 left font 'Sans,8' front noenhanced
set label "0.02" at graph 0.143545, graph 0.705893 left font 'Sans,8' front noenhanced
set label "0.01 (default)" at graph 0.136509, graph 0.671165 left font 'Sans,8' front noenhanced
set label "0.005" at graph 0.129308, graph 0.501441 left font 'Sans,8' front noenhanced
$decomposition_crescent_tick_0 << EOD
50235 0.00284106
EOD
$decomposition_crescent_tick_1 << EOD
24346 1.9786
24226 1.55812
25519 0.54542
24656 0.397924
23803 0.0852319
EOD
$decomposition_crescent_tick_front << EOD
23803 0.0852319
50235 0.00284106
EOD
plot $decomposition_crescent_tick_front using 1:2 with lines dt 2 lw 2 lc rgb '#888888' title 'Pareto front', \
  $decomposition_crescent_tick_0 using 1:2 with points pt 7 ps 1.6 lc rgb '#1f77b4' title "exact mesh pairs answered from it (the truth)" noenhanced, \
  $decomposition_crescent_tick_1 using 1:2 with linespoints lw 1.5 pt 5 ps 1.6 lc rgb '#d62728' title "hapticd-tick, concavity swept" noenhanced
