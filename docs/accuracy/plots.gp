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
set label "2mm" at graph 0.262663, graph 0.912978 left font 'Sans,8' front noenhanced
set label "1mm" at graph 0.441116, graph 0.912643 left font 'Sans,8' front noenhanced
set label "0.5mm" at graph 0.569327, graph 0.913303 left font 'Sans,8' front noenhanced
set label "0.25mm" at graph 0.704758, graph 0.915836 left font 'Sans,8' front noenhanced
$pairs_8_0 << EOD
861 1.67388e-16
EOD
$pairs_8_1 << EOD
1041 1.67388e-16
EOD
$pairs_8_2 << EOD
100 15.1584
EOD
$pairs_8_3 << EOD
1072 0.037277
EOD
$pairs_8_4 << EOD
471 0.976496
EOD
$pairs_8_5 << EOD
1642 0.976496
EOD
$pairs_8_6 << EOD
2073 5.02164e-15
EOD
$pairs_8_7 << EOD
1571 5.49364e-15
EOD
$pairs_8_8 << EOD
1312 1.61924
4819 1.5968
18193 1.64122
74019 1.8235
EOD
$pairs_8_front << EOD
100 15.1584
471 0.976496
861 1.67388e-16
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
set xrange [106.283:1.77828e+06]
set yrange [6.29794e-17:75.9909]
set xlabel 'median time per query (ns)'
set ylabel 'p99 force error (N)'
set title "What accuracy costs in time: pairs/32" noenhanced
set key at screen 0.65, screen 0.91 left top Left reverse font 'Sans,9' spacing 1.2
set arrow from 1e+06, graph 0 to 1e+06, graph 1 nohead dt 3 lw 1.5 lc rgb '#b00000' back
set label "1 kHz tick" at 1e+06, graph 0.97 right rotate by 90 offset -1.3,0 font 'Sans,8' tc rgb '#b00000'
set arrow from 250000, graph 0 to 250000, graph 1 nohead dt 3 lw 1.5 lc rgb '#b00000' back
set label "4 kHz tick" at 250000, graph 0.97 right rotate by 90 offset -1.3,0 font 'Sans,8' tc rgb '#b00000'
set label "2mm" at graph 0.364059, graph 0.903153 left font 'Sans,8' front noenhanced
set label "1mm" at graph 0.500894, graph 0.906912 left font 'Sans,8' front noenhanced
set label "0.5mm" at graph 0.639018, graph 0.90828 left font 'Sans,8' front noenhanced
set label "0.25mm" at graph 0.700408, graph 0.90844 left font 'Sans,8' front noenhanced
$pairs_32_0 << EOD
1703 5.97475e-15
EOD
$pairs_32_1 << EOD
1513 5.97475e-15
EOD
$pairs_32_2 << EOD
189 19.0881
EOD
$pairs_32_3 << EOD
1993 0.0373738
EOD
$pairs_32_4 << EOD
981 0.355001
EOD
$pairs_32_5 << EOD
2644 0.324079
EOD
$pairs_32_6 << EOD
3516 8.90573e-15
EOD
$pairs_32_7 << EOD
2614 9.62266e-15
EOD
$pairs_32_8 << EOD
3275 1.34775
12392 1.57608
47480 1.66848
192685 1.67964
EOD
$pairs_32_front << EOD
189 19.0881
981 0.355001
1513 5.97475e-15
1703 5.97475e-15
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
set xrange [242.369:1.77828e+06]
set yrange [6.37184e-17:77.7992]
set xlabel 'median time per query (ns)'
set ylabel 'p99 force error (N)'
set title "What accuracy costs in time: pairs/128" noenhanced
set key at screen 0.65, screen 0.91 left top Left reverse font 'Sans,9' spacing 1.2
set arrow from 1e+06, graph 0 to 1e+06, graph 1 nohead dt 3 lw 1.5 lc rgb '#b00000' back
set label "1 kHz tick" at 1e+06, graph 0.97 right rotate by 90 offset -1.3,0 font 'Sans,8' tc rgb '#b00000'
set arrow from 250000, graph 0 to 250000, graph 1 nohead dt 3 lw 1.5 lc rgb '#b00000' back
set label "4 kHz tick" at 250000, graph 0.97 right rotate by 90 offset -1.3,0 font 'Sans,8' tc rgb '#b00000'
set label "2mm" at graph 0.343907, graph 0.895944 left font 'Sans,8' front noenhanced
set label "1mm" at graph 0.484669, graph 0.899083 left font 'Sans,8' front noenhanced
set label "0.5mm" at graph 0.632378, graph 0.902287 left font 'Sans,8' front noenhanced
set label "0.25mm" at graph 0.785567, graph 0.903916 left font 'Sans,8' front noenhanced
$pairs_128_0 << EOD
3045 6.14985e-15
EOD
$pairs_128_1 << EOD
2735 6.04486e-15
EOD
$pairs_128_2 << EOD
431 19.5423
EOD
$pairs_128_3 << EOD
5820 0.0339337
EOD
$pairs_128_4 << EOD
3656 0.540271
EOD
$pairs_128_5 << EOD
3396 0.570367
EOD
$pairs_128_6 << EOD
9397 0.00433206
EOD
$pairs_128_7 << EOD
7013 1.38057e-14
EOD
$pairs_128_8 << EOD
4668 1.02081
16340 1.16336
60845 1.32942
237892 1.42276
EOD
$pairs_128_front << EOD
431 19.5423
2735 6.04486e-15
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
set xrange [16310.7:1.77828e+06]
set yrange [5.13112e-05:40.5418]
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
set label "8" at graph 0.386287, graph 0.108161 left font 'Sans,8' front noenhanced
set label "4" at graph 0.409008, graph 0.0847789 left font 'Sans,8' front noenhanced
set label "2" at graph 0.355033, graph 0.0847789 left font 'Sans,8' front noenhanced
set label "1" at graph 0.30727, graph 0.0847789 left font 'Sans,8' front noenhanced
set label "2 kHz" at graph 0.478183, graph 0.335236 left font 'Sans,8' front noenhanced
set label "4 kHz" at graph 0.429794, graph 0.39742 left font 'Sans,8' front noenhanced
set label "3.32mm" at graph 0.134268, graph 0.880961 left font 'Sans,8' front noenhanced
set label "1.66mm" at graph 0.239042, graph 0.898265 left font 'Sans,8' front noenhanced
set label "0.829mm" at graph 0.389964, graph 0.89156 left font 'Sans,8' front noenhanced
$scene_peg_in_hole_0 << EOD
77548 0.00016226
EOD
$scene_peg_in_hole_1 << EOD
102246 0.00016226
105260 0.00016226
95421 0.00016226
76265 0.00016226
EOD
$scene_peg_in_hole_2 << EOD
112384 0.026241
EOD
$scene_peg_in_hole_3 << EOD
145616 0.00486781
116042 0.0113258
EOD
$scene_peg_in_hole_4 << EOD
29005 8.05094
47419 10.1836
96263 9.29728
EOD
$scene_peg_in_hole_front << EOD
29005 8.05094
76265 0.00016226
77548 0.00016226
EOD
plot $scene_peg_in_hole_front using 1:2 with lines dt 2 lw 2 lc rgb '#888888' title 'Pareto front', \
  $scene_peg_in_hole_0 using 1:2 with points pt 7 ps 1.6 lc rgb '#1f77b4' title "hapticd-tick exact, budget unlimited, δ on (the truth)" noenhanced, \
  $scene_peg_in_hole_1 using 1:2 with linespoints lw 1.5 pt 5 ps 1.6 lc rgb '#d62728' title "hapticd-tick, budget swept" noenhanced, \
  $scene_peg_in_hole_2 using 1:2 with points pt 9 ps 1.6 lc rgb '#2ca02c' title "hapticd-tick δ off" noenhanced, \
  $scene_peg_in_hole_3 using 1:2 with linespoints lw 1.5 pt 11 ps 1.6 lc rgb '#9467bd' title "hapticd-tick, servo rate swept" noenhanced, \
  $scene_peg_in_hole_4 using 1:2 with linespoints lw 1.5 pt 13 ps 1.6 lc rgb '#ff7f0e' title "voxel-McNeely, h swept" noenhanced
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
set xrange [50499.4:1.77828e+06]
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
set label "0.1 N/tick" at graph 0.119948, graph 0.217397 left font 'Sans,8' front noenhanced
set label "0.25 N/tick" at graph 0.16834, graph 0.170633 left font 'Sans,8' front noenhanced
set label "0.5 N/tick (default)" at graph 0.275628, graph 0.213656 left font 'Sans,8' front noenhanced
set label "2 N/tick" at graph 0.305452, graph 0.174374 left font 'Sans,8' front noenhanced
set label "0° (shading off)" at graph 0.0415815, graph 0.157539 left font 'Sans,8' front noenhanced
set label "20°" at graph 0.22118, graph 0.213656 left font 'Sans,8' front noenhanced
set label "60°" at graph 0.256183, graph 0.157539 left font 'Sans,8' front noenhanced
set label "85°" at graph 0.130513, graph 0.230491 left font 'Sans,8' front noenhanced
$shaping_peg_in_hole_0 << EOD
89802 0.0333333
EOD
$shaping_peg_in_hole_1 << EOD
92365 0.0333333
111693 0.0333333
130096 0.0333333
144675 0.0333333
EOD
$shaping_peg_in_hole_2 << EOD
111241 0.0333333
107164 0.0333333
120679 0.0333333
96473 0.0333333
EOD
$shaping_peg_in_hole_front << EOD
89802 0.0333333
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
set xrange [69203.4:1.77828e+06]
set yrange [2.28228e-05:0.0300148]
set xlabel 'p99.9 time per tick (ns)'
set ylabel 'p99 force error (N)'
set title "What accuracy costs in time: scene/gears" noenhanced
set key at screen 0.65, screen 0.91 left top Left reverse font 'Sans,9' spacing 1.2
set arrow from 1e+06, graph 0 to 1e+06, graph 1 nohead dt 3 lw 1.5 lc rgb '#b00000' back
set label "1 kHz tick" at 1e+06, graph 0.97 right rotate by 90 offset -1.3,0 font 'Sans,8' tc rgb '#b00000'
set arrow from 250000, graph 0 to 250000, graph 1 nohead dt 3 lw 1.5 lc rgb '#b00000' back
set label "4 kHz tick" at 250000, graph 0.97 right rotate by 90 offset -1.3,0 font 'Sans,8' tc rgb '#b00000'
set arrow from graph 0, first 7.21721e-05 to graph 1, first 7.21721e-05 nohead dt 2 lc rgb '#999999' back
set label 'no error (exact)' at graph 0.99, first 7.21721e-05 right offset 0,0.7 font 'Sans,8' tc rgb '#666666'
set label "8" at graph 0.311251, graph 0.633903 left font 'Sans,8' front noenhanced
set label "4" at graph 0.250555, graph 0.701116 left font 'Sans,8' front noenhanced
set label "2" at graph 0.205942, graph 0.735025 left font 'Sans,8' front noenhanced
set label "1" at graph 0.188891, graph 0.807629 left font 'Sans,8' front noenhanced
set label "2 kHz" at graph 0.27507, graph 0.726681 left font 'Sans,8' front noenhanced
set label "4 kHz" at graph 0.316115, graph 0.6872 left font 'Sans,8' front noenhanced
$scene_gears_0 << EOD
207203 7.21721e-05
EOD
$scene_gears_1 << EOD
183079 0.00216516
150337 0.00350854
130067 0.00447598
123063 0.00753937
EOD
$scene_gears_2 << EOD
175134 7.21721e-05
EOD
$scene_gears_3 << EOD
183188 0.00356399
209298 0.00375535
EOD
$scene_gears_front << EOD
123063 0.00753937
130067 0.00447598
150337 0.00350854
175134 7.21721e-05
EOD
plot $scene_gears_front using 1:2 with lines dt 2 lw 2 lc rgb '#888888' title 'Pareto front', \
  $scene_gears_0 using 1:2 with points pt 7 ps 1.6 lc rgb '#1f77b4' title "hapticd-tick exact, budget unlimited, δ on (the truth)" noenhanced, \
  $scene_gears_1 using 1:2 with linespoints lw 1.5 pt 5 ps 1.6 lc rgb '#d62728' title "hapticd-tick, budget swept" noenhanced, \
  $scene_gears_2 using 1:2 with points pt 9 ps 1.6 lc rgb '#2ca02c' title "hapticd-tick δ off" noenhanced, \
  $scene_gears_3 using 1:2 with linespoints lw 1.5 pt 11 ps 1.6 lc rgb '#9467bd' title "hapticd-tick, servo rate swept" noenhanced
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
set xrange [110147:1.77828e+06]
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
set label "0.1 N/tick" at graph 0.0965537, graph 0.194015 left font 'Sans,8' front noenhanced
set label "0.25 N/tick" at graph 0.164609, graph 0.217397 left font 'Sans,8' front noenhanced
set label "0.5 N/tick (default)" at graph 0.0704152, graph 0.157539 left font 'Sans,8' front noenhanced
set label "2 N/tick" at graph 0.122169, graph 0.230491 left font 'Sans,8' front noenhanced
set label "0° (shading off)" at graph 0.218463, graph 0.174374 left font 'Sans,8' front noenhanced
set label "20°" at graph 0.218519, graph 0.230491 left font 'Sans,8' front noenhanced
set label "60°" at graph 0.285177, graph 0.213656 left font 'Sans,8' front noenhanced
set label "85°" at graph 0.160473, graph 0.174374 left font 'Sans,8' front noenhanced
$shaping_gears_0 << EOD
218234 0.0333333
EOD
$shaping_gears_1 << EOD
196062 0.0333333
202636 0.0333333
240227 0.0333333
199240 0.0333333
EOD
$shaping_gears_2 << EOD
196744 0.0333333
195872 0.0333333
236861 0.0333333
197574 0.0333333
EOD
$shaping_gears_front << EOD
195872 0.0333333
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
set xrange [12773:1.77828e+06]
set yrange [0.000491216:39.8107]
set xlabel 'p99.9 time per tick (ns)'
set ylabel 'p99 force error (N)'
set title "What accuracy costs in time: scene/dynamic" noenhanced
set key at screen 0.65, screen 0.91 left top Left reverse font 'Sans,9' spacing 1.2
set arrow from 1e+06, graph 0 to 1e+06, graph 1 nohead dt 3 lw 1.5 lc rgb '#b00000' back
set label "1 kHz tick" at 1e+06, graph 0.97 right rotate by 90 offset -1.3,0 font 'Sans,8' tc rgb '#b00000'
set arrow from 250000, graph 0 to 250000, graph 1 nohead dt 3 lw 1.5 lc rgb '#b00000' back
set label "4 kHz tick" at 250000, graph 0.97 right rotate by 90 offset -1.3,0 font 'Sans,8' tc rgb '#b00000'
set arrow from graph 0, first 0.00155336 to graph 1, first 0.00155336 nohead dt 2 lc rgb '#999999' back
set label 'no error (exact)' at graph 0.99, first 0.00155336 right offset 0,0.7 font 'Sans,8' tc rgb '#666666'
set label "8" at graph 0.470132, graph 0.402777 left font 'Sans,8' front noenhanced
set label "4" at graph 0.461181, graph 0.506614 left font 'Sans,8' front noenhanced
set label "2" at graph 0.402724, graph 0.470244 left font 'Sans,8' front noenhanced
set label "1" at graph 0.399782, graph 0.877769 left font 'Sans,8' front noenhanced
set label "2 kHz" at graph 0.397849, graph 0.786021 left font 'Sans,8' front noenhanced
set label "4 kHz" at graph 0.481898, graph 0.747605 left font 'Sans,8' front noenhanced
set label "7.63mm" at graph 0.0455461, graph 0.407911 left font 'Sans,8' front noenhanced
set label "3.82mm" at graph 0.161938, graph 0.407911 left font 'Sans,8' front noenhanced
set label "1.91mm" at graph 0.331518, graph 0.407911 left font 'Sans,8' front noenhanced
$scene_dynamic_0 << EOD
114457 0.00155336
EOD
$scene_dynamic_1 << EOD
122833 0.0466008
117524 0.150696
88067 0.0999017
86797 10
EOD
$scene_dynamic_2 << EOD
51457 0.18261
EOD
$scene_dynamic_3 << EOD
85973 3.54516
130178 2.29649
EOD
$scene_dynamic_4 << EOD
22714 0.0493849
26831 0.0493849
61968 0.0493849
EOD
$scene_dynamic_front << EOD
22714 0.0493849
114457 0.00155336
EOD
plot $scene_dynamic_front using 1:2 with lines dt 2 lw 2 lc rgb '#888888' title 'Pareto front', \
  $scene_dynamic_0 using 1:2 with points pt 7 ps 1.6 lc rgb '#1f77b4' title "hapticd-tick exact, budget unlimited, δ on (the truth)" noenhanced, \
  $scene_dynamic_1 using 1:2 with linespoints lw 1.5 pt 5 ps 1.6 lc rgb '#d62728' title "hapticd-tick, budget swept" noenhanced, \
  $scene_dynamic_2 using 1:2 with points pt 9 ps 1.6 lc rgb '#2ca02c' title "hapticd-tick δ off" noenhanced, \
  $scene_dynamic_3 using 1:2 with linespoints lw 1.5 pt 11 ps 1.6 lc rgb '#9467bd' title "hapticd-tick, servo rate swept" noenhanced, \
  $scene_dynamic_4 using 1:2 with linespoints lw 1.5 pt 13 ps 1.6 lc rgb '#ff7f0e' title "voxel-McNeely, h swept" noenhanced
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
set xrange [60285.2:1.77828e+06]
set yrange [0.00336169:19.5885]
set xlabel 'p99.9 time per tick (ns)'
set ylabel 'p99 force error (N)'
set title "What accuracy costs in time: dynamics/dynamic" noenhanced
set key at screen 0.65, screen 0.91 left top Left reverse font 'Sans,9' spacing 1.2
set arrow from 1e+06, graph 0 to 1e+06, graph 1 nohead dt 3 lw 1.5 lc rgb '#b00000' back
set label "1 kHz tick" at 1e+06, graph 0.97 right rotate by 90 offset -1.3,0 font 'Sans,8' tc rgb '#b00000'
set arrow from 250000, graph 0 to 250000, graph 1 nohead dt 3 lw 1.5 lc rgb '#b00000' back
set label "4 kHz tick" at 250000, graph 0.97 right rotate by 90 offset -1.3,0 font 'Sans,8' tc rgb '#b00000'
set arrow from graph 0, first 0.0106306 to graph 1, first 0.0106306 nohead dt 2 lc rgb '#999999' back
set label 'no error (exact)' at graph 0.99, first 0.0106306 right offset 0,0.7 font 'Sans,8' tc rgb '#666666'
set label "1" at graph 0.274007, graph 0.840656 left font 'Sans,8' front noenhanced
set label "4" at graph 0.279662, graph 0.749373 left font 'Sans,8' front noenhanced
set label "12 (default)" at graph 0.158786, graph 0.529262 left font 'Sans,8' front noenhanced
set label "32" at graph 0.305474, graph 0.583721 left font 'Sans,8' front noenhanced
set label "0" at graph 0.3009, graph 0.797608 left font 'Sans,8' front noenhanced
set label "2" at graph 0.334431, graph 0.828399 left font 'Sans,8' front noenhanced
set label "6 (default)" at graph 0.300935, graph 0.529262 left font 'Sans,8' front noenhanced
set label "18" at graph 0.280572, graph 0.501688 left font 'Sans,8' front noenhanced
$dynamics_dynamic_0 << EOD
107204 0.0106306
EOD
$dynamics_dynamic_1 << EOD
163880 4.92042
149365 2.22987
160515 0.330724
163000 0.530304
EOD
$dynamics_dynamic_2 << EOD
160496 3.38772
179783 4.42433
160515 0.330724
161127 0.318918
EOD
$dynamics_dynamic_front << EOD
107204 0.0106306
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
set xrange [54633.7:1.77828e+06]
set yrange [0.017547:38.9293]
set xlabel 'p99.9 time per tick (ns)'
set ylabel 'p99 force error (N)'
set title "What accuracy costs in time: scene/stress" noenhanced
set key at screen 0.65, screen 0.91 left top Left reverse font 'Sans,9' spacing 1.2
set arrow from 1e+06, graph 0 to 1e+06, graph 1 nohead dt 3 lw 1.5 lc rgb '#b00000' back
set label "1 kHz tick" at 1e+06, graph 0.97 right rotate by 90 offset -1.3,0 font 'Sans,8' tc rgb '#b00000'
set arrow from 250000, graph 0 to 250000, graph 1 nohead dt 3 lw 1.5 lc rgb '#b00000' back
set label "4 kHz tick" at 250000, graph 0.97 right rotate by 90 offset -1.3,0 font 'Sans,8' tc rgb '#b00000'
set arrow from graph 0, first 0.0554886 to graph 1, first 0.0554886 nohead dt 2 lc rgb '#999999' back
set label 'no error (exact)' at graph 0.99, first 0.0554886 right offset 0,0.7 font 'Sans,8' tc rgb '#666666'
set label "8" at graph 0.693936, graph 0.799153 left font 'Sans,8' front noenhanced
set label "4" at graph 0.635591, graph 0.658362 left font 'Sans,8' front noenhanced
set label "2" at graph 0.544403, graph 0.692949 left font 'Sans,8' front noenhanced
set label "1" at graph 0.502291, graph 0.63972 left font 'Sans,8' front noenhanced
set label "0.003" at graph 0.589142, graph 0.81014 left font 'Sans,8' front noenhanced
set label "0.01" at graph 0.736578, graph 0.815815 left font 'Sans,8' front noenhanced
set label "0.03" at graph 0.667238, graph 0.844067 left font 'Sans,8' front noenhanced
set label "2 kHz" at graph 0.522825, graph 0.592873 left font 'Sans,8' front noenhanced
set label "4 kHz" at graph 0.622755, graph 0.590878 left font 'Sans,8' front noenhanced
$scene_stress_0 << EOD
430940 0.0554886
EOD
$scene_stress_1 << EOD
660034 8.28375
480083 2.79982
349455 3.65479
301783 2.42524
EOD
$scene_stress_2 << EOD
661838 6.44246
EOD
$scene_stress_3 << EOD
408377 9.01556
682439 9.41849
597978 9.77861
EOD
$scene_stress_4 << EOD
324156 1.69044
459094 1.66466
EOD
$scene_stress_5 << EOD
97154 1.94852
EOD
$scene_stress_front << EOD
97154 1.94852
324156 1.69044
430940 0.0554886
EOD
plot $scene_stress_front using 1:2 with lines dt 2 lw 2 lc rgb '#888888' title 'Pareto front', \
  $scene_stress_0 using 1:2 with points pt 7 ps 1.6 lc rgb '#1f77b4' title "hapticd-tick exact, budget unlimited, δ on (the truth)" noenhanced, \
  $scene_stress_1 using 1:2 with linespoints lw 1.5 pt 5 ps 1.6 lc rgb '#d62728' title "hapticd-tick, budget swept" noenhanced, \
  $scene_stress_2 using 1:2 with points pt 9 ps 1.6 lc rgb '#2ca02c' title "hapticd-tick δ off" noenhanced, \
  $scene_stress_3 using 1:2 with linespoints lw 1.5 pt 11 ps 1.6 lc rgb '#9467bd' title "hapticd-tick, tessellation swept" noenhanced, \
  $scene_stress_4 using 1:2 with linespoints lw 1.5 pt 13 ps 1.6 lc rgb '#ff7f0e' title "hapticd-tick, servo rate swept" noenhanced, \
  $scene_stress_5 using 1:2 with points pt 4 ps 1.6 lc rgb '#8c564b' title "voxel-McNeely, h swept" noenhanced
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
set xrange [40346.3:1.77828e+06]
set yrange [0.00100627:1.09577]
set xlabel 'p99.9 time per tick (ns)'
set ylabel 'p99 force error (N)'
set title "What accuracy costs in time: dynamics/stack" noenhanced
set key at screen 0.65, screen 0.91 left top Left reverse font 'Sans,9' spacing 1.2
set arrow from 1e+06, graph 0 to 1e+06, graph 1 nohead dt 3 lw 1.5 lc rgb '#b00000' back
set label "1 kHz tick" at 1e+06, graph 0.97 right rotate by 90 offset -1.3,0 font 'Sans,8' tc rgb '#b00000'
set arrow from 250000, graph 0 to 250000, graph 1 nohead dt 3 lw 1.5 lc rgb '#b00000' back
set label "4 kHz tick" at 250000, graph 0.97 right rotate by 90 offset -1.3,0 font 'Sans,8' tc rgb '#b00000'
set arrow from graph 0, first 0.0031821 to graph 1, first 0.0031821 nohead dt 2 lc rgb '#999999' back
set label 'no error (exact)' at graph 0.99, first 0.0031821 right offset 0,0.7 font 'Sans,8' tc rgb '#666666'
set label "1" at graph 0.16362, graph 0.736332 left font 'Sans,8' front noenhanced
set label "4" at graph 0.196036, graph 0.781241 left font 'Sans,8' front noenhanced
set label "12 (default)" at graph 0.259369, graph 0.802437 left font 'Sans,8' front noenhanced
set label "32" at graph 0.257262, graph 0.65101 left font 'Sans,8' front noenhanced
set label "0" at graph 0.210312, graph 0.802437 left font 'Sans,8' front noenhanced
set label "2" at graph 0.243104, graph 0.825819 left font 'Sans,8' front noenhanced
set label "6 (default)" at graph 0.259369, graph 0.838913 left font 'Sans,8' front noenhanced
set label "18" at graph 0.232152, graph 0.779055 left font 'Sans,8' front noenhanced
$dynamics_stack_0 << EOD
161566 0.0031821
EOD
$dynamics_stack_1 << EOD
71747 0.173364
81115 0.237328
103094 0.275246
102275 0.0954629
EOD
$dynamics_stack_2 << EOD
97035 0.275246
103197 0.275246
103094 0.275246
100882 0.275246
EOD
$dynamics_stack_front << EOD
71747 0.173364
102275 0.0954629
161566 0.0031821
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
set xrange [1774.75:1.77828e+06]
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
set label "0.08" at graph 0.0948796, graph 0.836881 left font 'Sans,8' front noenhanced
set label "0.04" at graph 0.135444, graph 0.816554 left font 'Sans,8' front noenhanced
set label "0.02" at graph 0.148045, graph 0.689265 left font 'Sans,8' front noenhanced
set label "0.01 (default)" at graph 0.196994, graph 0.65387 left font 'Sans,8' front noenhanced
set label "0.005" at graph 0.201036, graph 0.537511 left font 'Sans,8' front noenhanced
$decomposition_crescent_0 << EOD
6781 0.00536117
EOD
$decomposition_crescent_1 << EOD
3156 2.03024
4177 1.70915
4557 0.581535
6391 0.430905
6572 0.160835
EOD
$decomposition_crescent_front << EOD
3156 2.03024
4177 1.70915
4557 0.581535
6391 0.430905
6572 0.160835
6781 0.00536117
EOD
plot $decomposition_crescent_front using 1:2 with lines dt 2 lw 2 lc rgb '#888888' title 'Pareto front', \
  $decomposition_crescent_0 using 1:2 with points pt 7 ps 1.6 lc rgb '#1f77b4' title "exact mesh brute force (the truth)" noenhanced, \
  $decomposition_crescent_1 using 1:2 with linespoints lw 1.5 pt 5 ps 1.6 lc rgb '#d62728' title "decomposition, concavity swept" noenhanced
