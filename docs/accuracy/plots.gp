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
set xrange [84.3512:1.77828e+06]
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
set label "2mm" at graph 0.262848, graph 0.912978 left font 'Sans,8' front noenhanced
set label "1mm" at graph 0.441741, graph 0.912643 left font 'Sans,8' front noenhanced
set label "0.5mm" at graph 0.575536, graph 0.913303 left font 'Sans,8' front noenhanced
set label "0.25mm" at graph 0.711695, graph 0.915836 left font 'Sans,8' front noenhanced
$pairs_8_0 << EOD
1412 1.67388e-16
EOD
$pairs_8_1 << EOD
1662 1.67388e-16
EOD
$pairs_8_2 << EOD
150 15.1584
EOD
$pairs_8_3 << EOD
1633 0.037277
EOD
$pairs_8_4 << EOD
561 0.976496
EOD
$pairs_8_5 << EOD
2063 0.976496
EOD
$pairs_8_6 << EOD
2744 5.02164e-15
EOD
$pairs_8_7 << EOD
1993 5.49364e-15
EOD
$pairs_8_8 << EOD
1743 1.61924
6111 1.5968
23154 1.64122
89819 1.8235
EOD
$pairs_8_front << EOD
150 15.1584
561 0.976496
1412 1.67388e-16
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
set xrange [101.221:1.77828e+06]
set yrange [6.29794e-17:75.9911]
set xlabel 'median time per query (ns)'
set ylabel 'p99 force error (N)'
set title "What accuracy costs in time: pairs/32" noenhanced
set key at screen 0.65, screen 0.91 left top Left reverse font 'Sans,9' spacing 1.2
set arrow from 1e+06, graph 0 to 1e+06, graph 1 nohead dt 3 lw 1.5 lc rgb '#b00000' back
set label "1 kHz tick" at 1e+06, graph 0.97 right rotate by 90 offset -1.3,0 font 'Sans,8' tc rgb '#b00000'
set arrow from 250000, graph 0 to 250000, graph 1 nohead dt 3 lw 1.5 lc rgb '#b00000' back
set label "4 kHz tick" at 250000, graph 0.97 right rotate by 90 offset -1.3,0 font 'Sans,8' tc rgb '#b00000'
set label "2mm" at graph 0.367323, graph 0.903153 left font 'Sans,8' front noenhanced
set label "1mm" at graph 0.50346, graph 0.906912 left font 'Sans,8' front noenhanced
set label "0.5mm" at graph 0.639659, graph 0.90828 left font 'Sans,8' front noenhanced
set label "0.25mm" at graph 0.698196, graph 0.90844 left font 'Sans,8' front noenhanced
$pairs_32_0 << EOD
1633 5.97475e-15
EOD
$pairs_32_1 << EOD
1453 5.97475e-15
EOD
$pairs_32_2 << EOD
180 19.0881
EOD
$pairs_32_3 << EOD
1923 0.0373738
EOD
$pairs_32_4 << EOD
952 0.355001
EOD
$pairs_32_5 << EOD
2655 0.324079
EOD
$pairs_32_6 << EOD
3497 8.90573e-15
EOD
$pairs_32_7 << EOD
2624 9.62266e-15
EOD
$pairs_32_8 << EOD
3276 1.34775
12394 1.57608
46918 1.66848
186473 1.67964
EOD
$pairs_32_front << EOD
180 19.0881
952 0.355001
1453 5.97475e-15
1633 5.97475e-15
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
set xrange [219.875:1.77828e+06]
set yrange [6.37184e-17:77.7993]
set xlabel 'median time per query (ns)'
set ylabel 'p99 force error (N)'
set title "What accuracy costs in time: pairs/128" noenhanced
set key at screen 0.65, screen 0.91 left top Left reverse font 'Sans,9' spacing 1.2
set arrow from 1e+06, graph 0 to 1e+06, graph 1 nohead dt 3 lw 1.5 lc rgb '#b00000' back
set label "1 kHz tick" at 1e+06, graph 0.97 right rotate by 90 offset -1.3,0 font 'Sans,8' tc rgb '#b00000'
set arrow from 250000, graph 0 to 250000, graph 1 nohead dt 3 lw 1.5 lc rgb '#b00000' back
set label "4 kHz tick" at 250000, graph 0.97 right rotate by 90 offset -1.3,0 font 'Sans,8' tc rgb '#b00000'
set label "2mm" at graph 0.340158, graph 0.895944 left font 'Sans,8' front noenhanced
set label "1mm" at graph 0.482693, graph 0.899083 left font 'Sans,8' front noenhanced
set label "0.5mm" at graph 0.632172, graph 0.902287 left font 'Sans,8' front noenhanced
set label "0.25mm" at graph 0.699253, graph 0.903916 left font 'Sans,8' front noenhanced
$pairs_128_0 << EOD
2725 6.14985e-15
EOD
$pairs_128_1 << EOD
2425 6.04486e-15
EOD
$pairs_128_2 << EOD
391 19.5423
EOD
$pairs_128_3 << EOD
5910 0.0339337
EOD
$pairs_128_4 << EOD
3877 0.540271
EOD
$pairs_128_5 << EOD
3126 0.570367
EOD
$pairs_128_6 << EOD
8696 0.00433206
EOD
$pairs_128_7 << EOD
6382 1.38057e-14
EOD
$pairs_128_8 << EOD
4229 1.02081
15249 1.16336
58530 1.32942
225155 1.42276
EOD
$pairs_128_front << EOD
391 19.5423
2425 6.04486e-15
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
set xrange [14474.1:1.77828e+06]
set yrange [5.13112e-05:46.5642]
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
set label "8" at graph 0.170108, graph 0.107305 left font 'Sans,8' front noenhanced
set label "4" at graph 0.130945, graph 0.083923 left font 'Sans,8' front noenhanced
set label "2" at graph 0.150697, graph 0.107305 left font 'Sans,8' front noenhanced
set label "1" at graph 0.15341, graph 0.0605411 left font 'Sans,8' front noenhanced
set label "2 kHz" at graph 0.177378, graph 0.331852 left font 'Sans,8' front noenhanced
set label "4 kHz" at graph 0.181489, graph 0.393407 left font 'Sans,8' front noenhanced
set label "3.32mm" at graph 0.131221, graph 0.872067 left font 'Sans,8' front noenhanced
set label "1.66mm" at graph 0.170777, graph 0.912578 left font 'Sans,8' front noenhanced
set label "0.829mm" at graph 0.328279, graph 0.882559 left font 'Sans,8' front noenhanced
$scene_peg_in_hole_0 << EOD
30889 0.00016226
EOD
$scene_peg_in_hole_1 << EOD
33603 0.00016226
30136 0.00016226
30607 0.00016226
31009 0.00016226
EOD
$scene_peg_in_hole_2 << EOD
34003 0.026241
EOD
$scene_peg_in_hole_3 << EOD
32139 0.00486781
32781 0.0113258
EOD
$scene_peg_in_hole_4 << EOD
50837 11.6964
EOD
$scene_peg_in_hole_5 << EOD
39895 0.00016226
EOD
$scene_peg_in_hole_6 << EOD
38203 0.00016226
EOD
$scene_peg_in_hole_7 << EOD
34404 0.00016226
EOD
$scene_peg_in_hole_8 << EOD
25739 8.05094
37982 10.1836
66424 9.29728
EOD
$scene_peg_in_hole_front << EOD
25739 8.05094
30136 0.00016226
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
set xrange [16851.7:1.77828e+06]
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
set label "0.1 N/tick" at graph 0.0787864, graph 0.217397 left font 'Sans,8' front noenhanced
set label "0.25 N/tick" at graph 0.0787641, graph 0.170633 left font 'Sans,8' front noenhanced
set label "0.5 N/tick (default)" at graph 0.164258, graph 0.194015 left font 'Sans,8' front noenhanced
set label "2 N/tick" at graph 0.162386, graph 0.230491 left font 'Sans,8' front noenhanced
set label "0° (shading off)" at graph 0.135263, graph 0.157539 left font 'Sans,8' front noenhanced
set label "20°" at graph 0.100074, graph 0.230491 left font 'Sans,8' front noenhanced
set label "60°" at graph 0.0874167, graph 0.157539 left font 'Sans,8' front noenhanced
set label "85°" at graph 0.0723174, graph 0.194015 left font 'Sans,8' front noenhanced
$shaping_peg_in_hole_0 << EOD
34195 0.0333333
EOD
$shaping_peg_in_hole_1 << EOD
30647 0.0333333
31360 0.0333333
34323 0.0333333
34025 0.0333333
EOD
$shaping_peg_in_hole_2 << EOD
29986 0.0333333
34104 0.0333333
32151 0.0333333
29967 0.0333333
EOD
$shaping_peg_in_hole_front << EOD
29967 0.0333333
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
set xrange [27505.2:1.77828e+06]
set yrange [3.06831e-05:0.168927]
set xlabel 'p99.9 time per tick (ns)'
set ylabel 'p99 force error (N)'
set title "What accuracy costs in time: scene/gears" noenhanced
set key at screen 0.65, screen 0.91 left top Left reverse font 'Sans,9' spacing 1.2
set arrow from 1e+06, graph 0 to 1e+06, graph 1 nohead dt 3 lw 1.5 lc rgb '#b00000' back
set label "1 kHz tick" at 1e+06, graph 0.97 right rotate by 90 offset -1.3,0 font 'Sans,8' tc rgb '#b00000'
set arrow from 250000, graph 0 to 250000, graph 1 nohead dt 3 lw 1.5 lc rgb '#b00000' back
set label "4 kHz tick" at 250000, graph 0.97 right rotate by 90 offset -1.3,0 font 'Sans,8' tc rgb '#b00000'
set arrow from graph 0, first 9.70283e-05 to graph 1, first 9.70283e-05 nohead dt 2 lc rgb '#999999' back
set label 'no error (exact)' at graph 0.99, first 9.70283e-05 right offset 0,0.7 font 'Sans,8' tc rgb '#666666'
set label "8" at graph 0.199112, graph 0.133661 left font 'Sans,8' front noenhanced
set label "4" at graph 0.180406, graph 0.569356 left font 'Sans,8' front noenhanced
set label "2" at graph 0.153595, graph 0.604816 left font 'Sans,8' front noenhanced
set label "1" at graph 0.116589, graph 0.582187 left font 'Sans,8' front noenhanced
set label "2 kHz" at graph 0.209437, graph 0.528529 left font 'Sans,8' front noenhanced
set label "4 kHz" at graph 0.210618, graph 0.560637 left font 'Sans,8' front noenhanced
$scene_gears_0 << EOD
60924 9.70283e-05
EOD
$scene_gears_1 << EOD
60114 9.70283e-05
55604 0.00413759
53271 0.00459122
48912 0.00462107
EOD
$scene_gears_2 << EOD
58330 9.70283e-05
EOD
$scene_gears_3 << EOD
62758 0.00291085
63068 0.00383823
EOD
$scene_gears_4 << EOD
71315 0.0424326
EOD
$scene_gears_5 << EOD
99979 0.0110428
EOD
$scene_gears_6 << EOD
91361 0.00830454
EOD
$scene_gears_7 << EOD
79901 0.00700686
EOD
$scene_gears_front << EOD
48912 0.00462107
53271 0.00459122
55604 0.00413759
58330 9.70283e-05
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
set xrange [32344.7:1.77828e+06]
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
set label "0.1 N/tick" at graph 0.131094, graph 0.217397 left font 'Sans,8' front noenhanced
set label "0.25 N/tick" at graph 0.0980407, graph 0.170633 left font 'Sans,8' front noenhanced
set label "0.5 N/tick (default)" at graph 0.200435, graph 0.194015 left font 'Sans,8' front noenhanced
set label "2 N/tick" at graph 0.0676831, graph 0.230491 left font 'Sans,8' front noenhanced
set label "0° (shading off)" at graph 0.155232, graph 0.157539 left font 'Sans,8' front noenhanced
set label "20°" at graph 0.170289, graph 0.230491 left font 'Sans,8' front noenhanced
set label "60°" at graph 0.105301, graph 0.157539 left font 'Sans,8' front noenhanced
set label "85°" at graph 0.0975839, graph 0.194015 left font 'Sans,8' front noenhanced
$shaping_gears_0 << EOD
59393 0.0333333
EOD
$shaping_gears_1 << EOD
66715 0.0333333
59612 0.0333333
68939 0.0333333
61064 0.0333333
EOD
$shaping_gears_2 << EOD
57518 0.0333333
61095 0.0333333
60564 0.0333333
58720 0.0333333
EOD
$shaping_gears_front << EOD
57518 0.0333333
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
set xrange [13589:1.77828e+06]
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
set label "8" at graph 0.261548, graph 0.290755 left font 'Sans,8' front noenhanced
set label "4" at graph 0.245551, graph 0.624445 left font 'Sans,8' front noenhanced
set label "2" at graph 0.261373, graph 0.483738 left font 'Sans,8' front noenhanced
set label "1" at graph 0.332113, graph 0.911764 left font 'Sans,8' front noenhanced
set label "2 kHz" at graph 0.231453, graph 0.822103 left font 'Sans,8' front noenhanced
set label "4 kHz" at graph 0.151009, graph 0.813247 left font 'Sans,8' front noenhanced
set label "7.63mm" at graph 0.0470277, graph 0.56134 left font 'Sans,8' front noenhanced
set label "3.82mm" at graph 0.186711, graph 0.56134 left font 'Sans,8' front noenhanced
set label "1.91mm" at graph 0.282172, graph 0.56134 left font 'Sans,8' front noenhanced
$scene_dynamic_0 << EOD
43512 1.99549e-05
EOD
$scene_dynamic_1 << EOD
45956 0.000598647
42509 0.111235
45917 0.0122869
64821 10
EOD
$scene_dynamic_2 << EOD
47320 0.323968
EOD
$scene_dynamic_3 << EOD
39686 2.45645
38221 2.13841
EOD
$scene_dynamic_4 << EOD
112302 10
EOD
$scene_dynamic_5 << EOD
82856 4.6067
EOD
$scene_dynamic_6 << EOD
84560 1.05185
EOD
$scene_dynamic_7 << EOD
63860 1.01392
EOD
$scene_dynamic_8 << EOD
24165 0.0414129
31910 0.0414129
50816 0.0414129
EOD
$scene_dynamic_front << EOD
24165 0.0414129
43512 1.99549e-05
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
set xrange [23527.8:1.77828e+06]
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
set label "1" at graph 0.167069, graph 0.732256 left font 'Sans,8' front noenhanced
set label "4" at graph 0.111603, graph 0.75964 left font 'Sans,8' front noenhanced
set label "12 (default)" at graph 0.0155962, graph 0.736944 left font 'Sans,8' front noenhanced
set label "32" at graph 0.197004, graph 0.735529 left font 'Sans,8' front noenhanced
set label "0" at graph 0.182375, graph 0.771703 left font 'Sans,8' front noenhanced
set label "2" at graph 0.146022, graph 0.801163 left font 'Sans,8' front noenhanced
set label "6 (default)" at graph 0.157745, graph 0.700468 left font 'Sans,8' front noenhanced
set label "18" at graph 0.123787, graph 0.70625 left font 'Sans,8' front noenhanced
$dynamics_dynamic_0 << EOD
56738 0.169996
EOD
$dynamics_dynamic_1 << EOD
46097 5.09988
41839 6.04639
44275 5.25069
52469 5.2047
EOD
$dynamics_dynamic_2 << EOD
49252 6.51731
45205 6.76829
44275 5.25069
46036 5.44289
EOD
$dynamics_dynamic_front << EOD
41839 6.04639
44275 5.25069
46097 5.09988
56738 0.169996
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
set xrange [42086.2:5.50457e+06]
set yrange [0.0224651:39.8828]
set xlabel 'p99.9 time per tick (ns)'
set ylabel 'p99 force error (N)'
set title "What accuracy costs in time: scene/stress" noenhanced
set key at screen 0.65, screen 0.91 left top Left reverse font 'Sans,9' spacing 1.2
set arrow from 1e+06, graph 0 to 1e+06, graph 1 nohead dt 3 lw 1.5 lc rgb '#b00000' back
set label "1 kHz tick" at 1e+06, graph 0.97 right rotate by 90 offset -1.3,0 font 'Sans,8' tc rgb '#b00000'
set arrow from 250000, graph 0 to 250000, graph 1 nohead dt 3 lw 1.5 lc rgb '#b00000' back
set label "4 kHz tick" at 250000, graph 0.97 right rotate by 90 offset -1.3,0 font 'Sans,8' tc rgb '#b00000'
set arrow from graph 0, first 0.071041 to graph 1, first 0.071041 nohead dt 2 lc rgb '#999999' back
set label 'no error (exact)' at graph 0.99, first 0.071041 right offset 0,0.7 font 'Sans,8' tc rgb '#666666'
set label "8" at graph 0.432795, graph 0.80994 left font 'Sans,8' front noenhanced
set label "4" at graph 0.334945, graph 0.770544 left font 'Sans,8' front noenhanced
set label "2" at graph 0.244063, graph 0.712077 left font 'Sans,8' front noenhanced
set label "1" at graph 0.182533, graph 0.712077 left font 'Sans,8' front noenhanced
set label "0.003" at graph 0.27063, graph 0.60848 left font 'Sans,8' front noenhanced
set label "0.01" at graph 0.297202, graph 0.640787 left font 'Sans,8' front noenhanced
set label "0.03" at graph 0.372552, graph 0.781749 left font 'Sans,8' front noenhanced
set label "2 kHz" at graph 0.27305, graph 0.701156 left font 'Sans,8' front noenhanced
set label "4 kHz" at graph 0.256535, graph 0.679174 left font 'Sans,8' front noenhanced
$scene_stress_0 << EOD
310275 0.071041
EOD
$scene_stress_1 << EOD
327867 9.62117
203512 7.16504
130686 4.6264
113754 4.6264
EOD
$scene_stress_2 << EOD
319211 3.66043
EOD
$scene_stress_3 << EOD
212029 2.13123
228111 3.14356
244449 7.79162
EOD
$scene_stress_4 << EOD
214544 4.26342
197953 3.61686
EOD
$scene_stress_5 << EOD
427937 10.0181
EOD
$scene_stress_6 << EOD
619147 4.97064
EOD
$scene_stress_7 << EOD
3.09545e+06 7.69927
EOD
$scene_stress_8 << EOD
2.7447e+06 8.03709
EOD
$scene_stress_9 << EOD
74841 3.07314
EOD
$scene_stress_front << EOD
74841 3.07314
212029 2.13123
310275 0.071041
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
set xrange [134243:1.77828e+06]
set yrange [1.13101e-10:10.6714]
set xlabel 'p99.9 time per tick (ns)'
set ylabel 'p99 force error (N)'
set title "What accuracy costs in time: shaping/stress" noenhanced
set key at screen 0.65, screen 0.91 left top Left reverse font 'Sans,9' spacing 1.2
set arrow from 1e+06, graph 0 to 1e+06, graph 1 nohead dt 3 lw 1.5 lc rgb '#b00000' back
set label "1 kHz tick" at 1e+06, graph 0.97 right rotate by 90 offset -1.3,0 font 'Sans,8' tc rgb '#b00000'
set arrow from 250000, graph 0 to 250000, graph 1 nohead dt 3 lw 1.5 lc rgb '#b00000' back
set label "4 kHz tick" at 250000, graph 0.97 right rotate by 90 offset -1.3,0 font 'Sans,8' tc rgb '#b00000'
set arrow from graph 0, first 3.57657e-10 to graph 1, first 3.57657e-10 nohead dt 2 lc rgb '#999999' back
set label 'no error (exact)' at graph 0.99, first 3.57657e-10 right offset 0,0.7 font 'Sans,8' tc rgb '#666666'
set label "0.1 N/tick" at graph 0.116908, graph 0.945329 left font 'Sans,8' front noenhanced
set label "0.25 N/tick" at graph 0.260732, graph 0.93339 left font 'Sans,8' front noenhanced
set label "0.5 N/tick (default)" at graph 0.252653, graph 0.0455591 left font 'Sans,8' front noenhanced
set label "2 N/tick" at graph 0.143876, graph 0.0652 left font 'Sans,8' front noenhanced
set label "0° (shading off)" at graph 0.0426294, graph 0.180152 left font 'Sans,8' front noenhanced
set label "20°" at graph 0.192548, graph 0.0259183 left font 'Sans,8' front noenhanced
set label "60°" at graph 0.249559, graph 0.082035 left font 'Sans,8' front noenhanced
set label "85°" at graph 0.173852, graph 0.082035 left font 'Sans,8' front noenhanced
$shaping_stress_0 << EOD
239511 3.57657e-10
EOD
$shaping_stress_1 << EOD
241736 2.68053
255551 1.98239
250272 3.57657e-10
245183 3.57657e-10
EOD
$shaping_stress_2 << EOD
238721 1.07297e-08
250953 3.57657e-10
248279 3.57657e-10
240142 3.57657e-10
EOD
$shaping_stress_front << EOD
238721 1.07297e-08
239511 3.57657e-10
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
set xrange [20598:1.77828e+06]
set yrange [0.00093633:0.881178]
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
set label "1" at graph 0.148818, graph 0.821609 left font 'Sans,8' front noenhanced
set label "4" at graph 0.107633, graph 0.79728 left font 'Sans,8' front noenhanced
set label "12 (default)" at graph 0.201568, graph 0.797137 left font 'Sans,8' front noenhanced
set label "32" at graph 0.240972, graph 0.664884 left font 'Sans,8' front noenhanced
set label "0" at graph 0.167394, graph 0.820519 left font 'Sans,8' front noenhanced
set label "2" at graph 0.171497, graph 0.773755 left font 'Sans,8' front noenhanced
set label "6 (default)" at graph 0.201568, graph 0.833612 left font 'Sans,8' front noenhanced
set label "18" at graph 0.131869, graph 0.777496 left font 'Sans,8' front noenhanced
$dynamics_stack_0 << EOD
116279 0.00296094
EOD
$dynamics_stack_1 << EOD
40885 0.221342
36629 0.219912
48050 0.219696
57278 0.0888281
EOD
$dynamics_stack_2 << EOD
44415 0.219696
45235 0.219696
48050 0.219696
42340 0.219696
EOD
$dynamics_stack_front << EOD
36629 0.219912
42340 0.219696
57278 0.0888281
116279 0.00296094
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
set xrange [1796.68:1.77828e+06]
set yrange [0.00169535:8.08253]
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
set label "0.08" at graph 0.095028, graph 0.836881 left font 'Sans,8' front noenhanced
set label "0.04" at graph 0.0997459, graph 0.793172 left font 'Sans,8' front noenhanced
set label "0.02" at graph 0.143356, graph 0.689265 left font 'Sans,8' front noenhanced
set label "0.01 (default)" at graph 0.19305, graph 0.65387 left font 'Sans,8' front noenhanced
set label "0.005" at graph 0.204388, graph 0.537511 left font 'Sans,8' front noenhanced
$decomposition_crescent_0 << EOD
6682 0.00536117
EOD
$decomposition_crescent_1 << EOD
3195 2.03024
4099 1.70915
4459 0.581535
6282 0.430905
6793 0.160835
EOD
$decomposition_crescent_front << EOD
3195 2.03024
4099 1.70915
4459 0.581535
6282 0.430905
6682 0.00536117
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
set xrange [12908:1.77828e+06]
set yrange [0.000898423:7.87695]
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
set label "0.08" at graph 0.158056, graph 0.847827 left font 'Sans,8' front noenhanced
set label "0.04" at graph 0.138465, graph 0.821512 left font 'Sans,8' front noenhanced
set label "0.02" at graph 0.158216, graph 0.705893 left font 'Sans,8' front noenhanced
set label "0.01 (default)" at graph 0.140984, graph 0.671165 left font 'Sans,8' front noenhanced
set label "0.005" at graph 0.12844, graph 0.501441 left font 'Sans,8' front noenhanced
$decomposition_crescent_tick_0 << EOD
53291 0.00284106
EOD
$decomposition_crescent_tick_1 << EOD
26559 1.9786
24116 1.55812
26580 0.54542
24417 0.397924
22954 0.0852319
EOD
$decomposition_crescent_tick_front << EOD
22954 0.0852319
53291 0.00284106
EOD
plot $decomposition_crescent_tick_front using 1:2 with lines dt 2 lw 2 lc rgb '#888888' title 'Pareto front', \
  $decomposition_crescent_tick_0 using 1:2 with points pt 7 ps 1.6 lc rgb '#1f77b4' title "exact mesh pairs answered from it (the truth)" noenhanced, \
  $decomposition_crescent_tick_1 using 1:2 with linespoints lw 1.5 pt 5 ps 1.6 lc rgb '#d62728' title "hapticd-tick, concavity swept" noenhanced
