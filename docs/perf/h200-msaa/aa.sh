#!/bin/bash
# H200 timings for issue 17: MSAA 1/2/4/8x, bloom, the post AA modes and their edge variants, on one frame each
S=.assets/lee-perry-smith/LeePerrySmith.glb
O=/tmp/aa; mkdir -p $O
run() { n=$1; shift; .bin/dermis bench --scene $S "$@" --warmup 30 --frames 50 --report $O/$n.json > $O/$n.txt 2>&1 || echo "FAILED $n" >> $O/failed.txt; }
for r in 1280x720 1920x1080; do W=${r%x*}; H=${r#*x}
  for m in 1 2 4 8; do run portrait-$r-msaa$m --width $W --height $H --msaa $m; done
  run portrait-$r-bloom --width $W --height $H --bloom
  for aa in fxaa mlaa smaa; do run portrait-$r-$aa --width $W --height $H --aa $aa; done
  run portrait-$r-mlaa-depth --width $W --height $H --aa mlaa --aa-edges depth
  run portrait-$r-smaa-color --width $W --height $H --aa smaa --aa-edges color
  for p in low medium ultra; do run portrait-$r-smaa-$p --width $W --height $H --aa smaa --smaa-preset $p; done
done
for m in 1 4 8; do run crowd16-1280x720-msaa$m --width 1280 --height 720 --heads 16 --distance 4 --msaa $m; done
for aa in fxaa mlaa smaa; do run crowd16-1280x720-$aa --width 1280 --height 720 --heads 16 --distance 4 --aa $aa; done
