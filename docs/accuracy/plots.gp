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
set xrange [60.7025:1.77828e+06]
set yrange [5.29327e-17:60.3467]
set xlabel 'mean time per query (ns)'
set ylabel 'p99 force error (N)'
set title "What accuracy costs in time: pairs/8" noenhanced
set key at screen 0.65, screen 0.91 left top Left reverse font 'Sans,9' spacing 1.2
set arrow from 1e+06, graph 0 to 1e+06, graph 1 nohead dt 3 lw 1.5 lc rgb '#b00000' back
set label "1 kHz tick" at 1e+06, graph 0.97 right rotate by 90 offset -1.3,0 font 'Sans,8' tc rgb '#b00000'
set arrow from 250000, graph 0 to 250000, graph 1 nohead dt 3 lw 1.5 lc rgb '#b00000' back
set label "4 kHz tick" at 250000, graph 0.97 right rotate by 90 offset -1.3,0 font 'Sans,8' tc rgb '#b00000'
set arrow from graph 0, first 1.67388e-16 to graph 1, first 1.67388e-16 nohead dt 2 lc rgb '#999999' back
set label 'no error (exact)' at graph 0.99, first 1.67388e-16 right offset 0,0.7 font 'Sans,8' tc rgb '#666666'
set label "2mm" at graph 0.252995, graph 0.912978 left font 'Sans,8' front noenhanced
set label "1mm" at graph 0.464096, graph 0.912643 left font 'Sans,8' front noenhanced
set label "0.5mm" at graph 0.556667, graph 0.913303 left font 'Sans,8' front noenhanced
set label "0.25mm" at graph 0.687863, graph 0.915836 left font 'Sans,8' front noenhanced
$pairs_8_0 << EOD
606.684 1.67388e-16
EOD
$pairs_8_1 << EOD
787.713 1.67388e-16
EOD
$pairs_8_2 << EOD
107.946 15.1584
EOD
$pairs_8_3 << EOD
1078.36 0.037277
EOD
$pairs_8_4 << EOD
405.368 0.976496
EOD
$pairs_8_5 << EOD
1498.19 0.976496
EOD
$pairs_8_6 << EOD
1768.5 5.02164e-15
EOD
$pairs_8_7 << EOD
1258.94 5.49364e-15
EOD
$pairs_8_8 << EOD
1252.74 1.61924
6375.98 1.5968
16521.2 1.64122
63689.6 1.8235
EOD
$pairs_8_front << EOD
107.946 15.1584
405.368 0.976496
606.684 1.67388e-16
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
set xrange [102.061:1.77828e+06]
set yrange [6.29794e-17:75.9911]
set xlabel 'mean time per query (ns)'
set ylabel 'p99 force error (N)'
set title "What accuracy costs in time: pairs/32" noenhanced
set key at screen 0.65, screen 0.91 left top Left reverse font 'Sans,9' spacing 1.2
set arrow from 1e+06, graph 0 to 1e+06, graph 1 nohead dt 3 lw 1.5 lc rgb '#b00000' back
set label "1 kHz tick" at 1e+06, graph 0.97 right rotate by 90 offset -1.3,0 font 'Sans,8' tc rgb '#b00000'
set arrow from 250000, graph 0 to 250000, graph 1 nohead dt 3 lw 1.5 lc rgb '#b00000' back
set label "4 kHz tick" at 250000, graph 0.97 right rotate by 90 offset -1.3,0 font 'Sans,8' tc rgb '#b00000'
set label "2mm" at graph 0.358042, graph 0.903153 left font 'Sans,8' front noenhanced
set label "1mm" at graph 0.49215, graph 0.906912 left font 'Sans,8' front noenhanced
set label "0.5mm" at graph 0.628078, graph 0.90828 left font 'Sans,8' front noenhanced
set label "0.25mm" at graph 0.765253, graph 0.90844 left font 'Sans,8' front noenhanced
$pairs_32_0 << EOD
1523.36 5.97475e-15
EOD
$pairs_32_1 << EOD
1180.48 5.97475e-15
EOD
$pairs_32_2 << EOD
181.493 19.0881
EOD
$pairs_32_3 << EOD
1818.49 0.0373738
EOD
$pairs_32_4 << EOD
829.011 0.355001
EOD
$pairs_32_5 << EOD
2372.95 0.324079
EOD
$pairs_32_6 << EOD
2953.11 8.90573e-15
EOD
$pairs_32_7 << EOD
2171.55 9.62266e-15
EOD
$pairs_32_8 << EOD
3008.12 1.34775
11144.6 1.57608
42029.6 1.66848
160448 1.67964
EOD
$pairs_32_front << EOD
181.493 19.0881
829.011 0.355001
1180.48 5.97475e-15
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
set xrange [199.585:1.77828e+06]
set yrange [6.37184e-17:77.7993]
set xlabel 'mean time per query (ns)'
set ylabel 'p99 force error (N)'
set title "What accuracy costs in time: pairs/128" noenhanced
set key at screen 0.65, screen 0.91 left top Left reverse font 'Sans,9' spacing 1.2
set arrow from 1e+06, graph 0 to 1e+06, graph 1 nohead dt 3 lw 1.5 lc rgb '#b00000' back
set label "1 kHz tick" at 1e+06, graph 0.97 right rotate by 90 offset -1.3,0 font 'Sans,8' tc rgb '#b00000'
set arrow from 250000, graph 0 to 250000, graph 1 nohead dt 3 lw 1.5 lc rgb '#b00000' back
set label "4 kHz tick" at 250000, graph 0.97 right rotate by 90 offset -1.3,0 font 'Sans,8' tc rgb '#b00000'
set label "2mm" at graph 0.33857, graph 0.895944 left font 'Sans,8' front noenhanced
set label "1mm" at graph 0.474431, graph 0.899083 left font 'Sans,8' front noenhanced
set label "0.5mm" at graph 0.616549, graph 0.902287 left font 'Sans,8' front noenhanced
set label "0.25mm" at graph 0.764586, graph 0.903916 left font 'Sans,8' front noenhanced
$pairs_128_0 << EOD
2135.69 6.14985e-15
EOD
$pairs_128_1 << EOD
1863.09 6.04486e-15
EOD
$pairs_128_2 << EOD
354.918 19.5423
EOD
$pairs_128_3 << EOD
4531.37 0.0339337
EOD
$pairs_128_4 << EOD
2723.95 0.540271
EOD
$pairs_128_5 << EOD
2866.42 0.570367
EOD
$pairs_128_6 << EOD
7177.5 0.00433206
EOD
$pairs_128_7 << EOD
5312.08 1.38057e-14
EOD
$pairs_128_8 << EOD
3906.04 1.02081
13439 1.16336
48946.1 1.32942
188123 1.42276
EOD
$pairs_128_front << EOD
354.918 19.5423
1863.09 6.04486e-15
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
set xrange [1010.3:1.77828e+06]
set yrange [0.000276824:40.5902]
set xlabel 'mean time per tick (ns)'
set ylabel 'p99 force error (N)'
set title "What accuracy costs in time: scene/peg_in_hole" noenhanced
set key at screen 0.65, screen 0.91 left top Left reverse font 'Sans,9' spacing 1.2
set arrow from 1e+06, graph 0 to 1e+06, graph 1 nohead dt 3 lw 1.5 lc rgb '#b00000' back
set label "1 kHz tick" at 1e+06, graph 0.97 right rotate by 90 offset -1.3,0 font 'Sans,8' tc rgb '#b00000'
set arrow from 250000, graph 0 to 250000, graph 1 nohead dt 3 lw 1.5 lc rgb '#b00000' back
set label "4 kHz tick" at 250000, graph 0.97 right rotate by 90 offset -1.3,0 font 'Sans,8' tc rgb '#b00000'
set arrow from graph 0, first 0.000875393 to graph 1, first 0.000875393 nohead dt 2 lc rgb '#999999' back
set label 'no error (exact)' at graph 0.99, first 0.000875393 right offset 0,0.7 font 'Sans,8' tc rgb '#666666'
set label "8" at graph 0.156411, graph 0.0967826 left font 'Sans,8' front noenhanced
set label "4" at graph 0.121697, graph 0.0967826 left font 'Sans,8' front noenhanced
set label "2" at graph 0.103553, graph 0.120165 left font 'Sans,8' front noenhanced
set label "1" at graph 0.0644147, graph 0.0967826 left font 'Sans,8' front noenhanced
set label "3.32mm" at graph 0.0885988, graph 0.863933 left font 'Sans,8' front noenhanced
set label "1.66mm" at graph 0.263055, graph 0.883861 left font 'Sans,8' front noenhanced
set label "0.829mm" at graph 0.447297, graph 0.876105 left font 'Sans,8' front noenhanced
$scene_peg_in_hole_0 << EOD
3009.7 0.000875393
EOD
$scene_peg_in_hole_1 << EOD
2982.21 0.000875393
2945.51 0.000875393
2273.16 0.000875393
1919.77 0.000875393
EOD
$scene_peg_in_hole_2 << EOD
2930.27 0.0262618
EOD
$scene_peg_in_hole_3 << EOD
1796.59 8.04397
6616.91 10.1958
26219.3 9.29719
EOD
$scene_peg_in_hole_front << EOD
1796.59 8.04397
1919.77 0.000875393
EOD
plot $scene_peg_in_hole_front using 1:2 with lines dt 2 lw 2 lc rgb '#888888' title 'Pareto front', \
  $scene_peg_in_hole_0 using 1:2 with points pt 7 ps 1.6 lc rgb '#1f77b4' title "hapticd-tick exact, budget unlimited, δ on (the truth)" noenhanced, \
  $scene_peg_in_hole_1 using 1:2 with linespoints lw 1.5 pt 5 ps 1.6 lc rgb '#d62728' title "hapticd-tick, budget swept" noenhanced, \
  $scene_peg_in_hole_2 using 1:2 with points pt 9 ps 1.6 lc rgb '#2ca02c' title "hapticd-tick δ off" noenhanced, \
  $scene_peg_in_hole_3 using 1:2 with linespoints lw 1.5 pt 11 ps 1.6 lc rgb '#9467bd' title "voxel-McNeely, h swept" noenhanced
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
set xrange [4645.45:1.77828e+06]
set yrange [9.76207e-07:0.0296921]
set xlabel 'mean time per tick (ns)'
set ylabel 'p99 force error (N)'
set title "What accuracy costs in time: scene/gears" noenhanced
set key at screen 0.65, screen 0.91 left top Left reverse font 'Sans,9' spacing 1.2
set arrow from 1e+06, graph 0 to 1e+06, graph 1 nohead dt 3 lw 1.5 lc rgb '#b00000' back
set label "1 kHz tick" at 1e+06, graph 0.97 right rotate by 90 offset -1.3,0 font 'Sans,8' tc rgb '#b00000'
set arrow from 250000, graph 0 to 250000, graph 1 nohead dt 3 lw 1.5 lc rgb '#b00000' back
set label "4 kHz tick" at 250000, graph 0.97 right rotate by 90 offset -1.3,0 font 'Sans,8' tc rgb '#b00000'
set arrow from graph 0, first 3.08704e-06 to graph 1, first 3.08704e-06 nohead dt 2 lc rgb '#999999' back
set label 'no error (exact)' at graph 0.99, first 3.08704e-06 right offset 0,0.7 font 'Sans,8' tc rgb '#666666'
set label "8" at graph 0.148261, graph 0.441017 left font 'Sans,8' front noenhanced
set label "4" at graph 0.123986, graph 0.831953 left font 'Sans,8' front noenhanced
set label "2" at graph 0.114505, graph 0.86495 left font 'Sans,8' front noenhanced
set label "1" at graph 0.0753001, graph 0.866164 left font 'Sans,8' front noenhanced
$scene_gears_0 << EOD
11485.4 3.08704e-06
EOD
$scene_gears_1 << EOD
10473.6 9.26111e-05
9065.55 0.00523924
8568.52 0.00736546
8260.9 0.00745831
EOD
$scene_gears_2 << EOD
11231.3 3.08704e-06
EOD
$scene_gears_front << EOD
8260.9 0.00745831
8568.52 0.00736546
9065.55 0.00523924
10473.6 9.26111e-05
11231.3 3.08704e-06
EOD
plot $scene_gears_front using 1:2 with lines dt 2 lw 2 lc rgb '#888888' title 'Pareto front', \
  $scene_gears_0 using 1:2 with points pt 7 ps 1.6 lc rgb '#1f77b4' title "hapticd-tick exact, budget unlimited, δ on (the truth)" noenhanced, \
  $scene_gears_1 using 1:2 with linespoints lw 1.5 pt 5 ps 1.6 lc rgb '#d62728' title "hapticd-tick, budget swept" noenhanced, \
  $scene_gears_2 using 1:2 with points pt 9 ps 1.6 lc rgb '#2ca02c' title "hapticd-tick δ off" noenhanced
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
set xrange [450.452:1.77828e+06]
set yrange [0.0169018:39.8107]
set xlabel 'mean time per tick (ns)'
set ylabel 'p99 force error (N)'
set title "What accuracy costs in time: scene/dynamic" noenhanced
set key at screen 0.65, screen 0.91 left top Left reverse font 'Sans,9' spacing 1.2
set arrow from 1e+06, graph 0 to 1e+06, graph 1 nohead dt 3 lw 1.5 lc rgb '#b00000' back
set label "1 kHz tick" at 1e+06, graph 0.97 right rotate by 90 offset -1.3,0 font 'Sans,8' tc rgb '#b00000'
set arrow from 250000, graph 0 to 250000, graph 1 nohead dt 3 lw 1.5 lc rgb '#b00000' back
set label "4 kHz tick" at 250000, graph 0.97 right rotate by 90 offset -1.3,0 font 'Sans,8' tc rgb '#b00000'
set arrow from graph 0, first 0.0534483 to graph 1, first 0.0534483 nohead dt 2 lc rgb '#999999' back
set label 'no error (exact)' at graph 0.99, first 0.0534483 right offset 0,0.7 font 'Sans,8' tc rgb '#666666'
set label "8" at graph 0.439912, graph 0.783827 left font 'Sans,8' front noenhanced
set label "4" at graph 0.381145, graph 0.820917 left font 'Sans,8' front noenhanced
set label "2" at graph 0.400239, graph 0.845138 left font 'Sans,8' front noenhanced
set label "1" at graph 0.438785, graph 0.822068 left font 'Sans,8' front noenhanced
set label "7.63mm" at graph 0.0810851, graph 0.586323 left font 'Sans,8' front noenhanced
set label "3.82mm" at graph 0.218713, graph 0.586323 left font 'Sans,8' front noenhanced
set label "1.91mm" at graph 0.385962, graph 0.586323 left font 'Sans,8' front noenhanced
$scene_dynamic_0 << EOD
18246.7 0.0534483
EOD
$scene_dynamic_1 << EOD
15635.6 7.43107
12637.4 9.91104
12908.7 9.97581
15490.4 10
EOD
$scene_dynamic_2 << EOD
18139.2 3.3286
EOD
$scene_dynamic_3 << EOD
801.029 1.60345
2503.83 1.60345
10002.1 1.60345
EOD
$scene_dynamic_front << EOD
801.029 1.60345
18246.7 0.0534483
EOD
plot $scene_dynamic_front using 1:2 with lines dt 2 lw 2 lc rgb '#888888' title 'Pareto front', \
  $scene_dynamic_0 using 1:2 with points pt 7 ps 1.6 lc rgb '#1f77b4' title "hapticd-tick exact, budget unlimited, δ on (the truth)" noenhanced, \
  $scene_dynamic_1 using 1:2 with linespoints lw 1.5 pt 5 ps 1.6 lc rgb '#d62728' title "hapticd-tick, budget swept" noenhanced, \
  $scene_dynamic_2 using 1:2 with points pt 9 ps 1.6 lc rgb '#2ca02c' title "hapticd-tick δ off" noenhanced, \
  $scene_dynamic_3 using 1:2 with linespoints lw 1.5 pt 11 ps 1.6 lc rgb '#9467bd' title "voxel-McNeely, h swept" noenhanced
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
set xrange [4973.16:1.77828e+06]
set yrange [0.030143:37.8507]
set xlabel 'mean time per tick (ns)'
set ylabel 'p99 force error (N)'
set title "What accuracy costs in time: scene/stress" noenhanced
set key at screen 0.65, screen 0.91 left top Left reverse font 'Sans,9' spacing 1.2
set arrow from 1e+06, graph 0 to 1e+06, graph 1 nohead dt 3 lw 1.5 lc rgb '#b00000' back
set label "1 kHz tick" at 1e+06, graph 0.97 right rotate by 90 offset -1.3,0 font 'Sans,8' tc rgb '#b00000'
set arrow from 250000, graph 0 to 250000, graph 1 nohead dt 3 lw 1.5 lc rgb '#b00000' back
set label "4 kHz tick" at 250000, graph 0.97 right rotate by 90 offset -1.3,0 font 'Sans,8' tc rgb '#b00000'
set arrow from graph 0, first 0.0953207 to graph 1, first 0.0953207 nohead dt 2 lc rgb '#999999' back
set label 'no error (exact)' at graph 0.99, first 0.0953207 right offset 0,0.7 font 'Sans,8' tc rgb '#666666'
set label "8" at graph 0.440499, graph 0.749244 left font 'Sans,8' front noenhanced
set label "4" at graph 0.220375, graph 0.80626 left font 'Sans,8' front noenhanced
set label "2" at graph 0.172141, graph 0.806382 left font 'Sans,8' front noenhanced
set label "1" at graph 0.10948, graph 0.777229 left font 'Sans,8' front noenhanced
$scene_stress_0 << EOD
99753.9 0.0953207
EOD
$scene_stress_1 << EOD
61921.9 6.32426
16974.1 9.49939
12782.9 9.50766
8843.67 7.72203
EOD
$scene_stress_2 << EOD
107579 2.85962
EOD
$scene_stress_3 << EOD
15025.3 6.53751
EOD
$scene_stress_front << EOD
8843.67 7.72203
15025.3 6.53751
61921.9 6.32426
99753.9 0.0953207
EOD
plot $scene_stress_front using 1:2 with lines dt 2 lw 2 lc rgb '#888888' title 'Pareto front', \
  $scene_stress_0 using 1:2 with points pt 7 ps 1.6 lc rgb '#1f77b4' title "hapticd-tick exact, budget unlimited, δ on (the truth)" noenhanced, \
  $scene_stress_1 using 1:2 with linespoints lw 1.5 pt 5 ps 1.6 lc rgb '#d62728' title "hapticd-tick, budget swept" noenhanced, \
  $scene_stress_2 using 1:2 with points pt 9 ps 1.6 lc rgb '#2ca02c' title "hapticd-tick δ off" noenhanced, \
  $scene_stress_3 using 1:2 with points pt 11 ps 1.6 lc rgb '#9467bd' title "voxel-McNeely, h swept" noenhanced
