# Bucky's transfer function (docs/guide.md, "Transfer functions"), over density 0..40 after normalisation:
# the thin outer shell a warm orange, the denser carbon cages pale blue, the cores white.
# density  r     g     b
0          0.95  0.55  0.20
10         0.95  0.70  0.35
25         0.55  0.75  0.95
40         0.98  0.98  0.98
