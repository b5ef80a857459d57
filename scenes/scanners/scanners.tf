# The scanner fixtures' transfer function (docs/guide.md, "Transfer functions"), over density 0..40
# after normalisation: thin voxels orange, dense ones pale blue.
# density  r     g     b
0          0.95  0.55  0.20
40         0.55  0.75  0.95
