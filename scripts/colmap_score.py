"""Scores COLMAP's verified image pairs (two_view_geometries) as tests/real_place_test.cc scores patrolmap."""
import math
import sqlite3
import sys

scratch, poses_path = sys.argv[1], sys.argv[2]
MIN_GAP, SAME_PLACE_M = 3, 5.0
REVISITS = {frozenset(p) for p in [("dbow2_1.png", "dbow2_3.png"), ("euroc_0.png", "euroc_1.png"),
                                   ("euroc_2.png", "euroc_3.png"), ("graf1.png", "graf3.png"),
                                   ("leuvenA.jpg", "leuvenB.jpg"), ("aero1.jpg", "aero3.jpg")]}


def verified_pairs(database):
    """{(name_a, name_b): inliers} of the pairs COLMAP verified (config > 1: a geometry was found)."""
    db = sqlite3.connect(database)
    names = dict(db.execute("SELECT image_id, name FROM images"))
    pairs = {}
    for pair_id, rows, config in db.execute("SELECT pair_id, rows, config FROM two_view_geometries"):
        second = pair_id % 2147483647
        first = (pair_id - second) // 2147483647
        if config > 1 and rows > 0:
            pairs[(names[first], names[second])] = rows
    return pairs


pairs = verified_pairs(f"{scratch}/pairs.db")
found = sum(1 for p in pairs if frozenset(p) in REVISITS)
false = sum(1 for p in pairs if frozenset(p) not in REVISITS)
print(f"COLMAP pairs: revisits {len(REVISITS)}: found {found}; other pairs 85: accepted {false}")

centres = []
for line in open(poses_path):
    v = [float(x) for x in line.split()]
    centres.append((v[3], v[7], v[11]))
kitti = verified_pairs(f"{scratch}/kitti.db")
frame = lambda name: int(name.split(".")[0])
inliers = {}
for (a, b), rows in kitti.items():
    inliers[(frame(a), frame(b))] = inliers[(frame(b), frame(a))] = rows
findable = closures = true = 0
for j in range(len(centres)):
    earlier = [i for i in range(0, j - MIN_GAP + 1)]
    findable += any(math.dist(centres[i], centres[j]) <= SAME_PLACE_M for i in earlier)
    verified = [(inliers[(i, j)], i) for i in earlier if (i, j) in inliers]
    if not verified:
        continue
    best = max(verified)[1]  # the earlier frame with the most inliers
    closures += 1
    true += math.dist(centres[best], centres[j]) <= SAME_PLACE_M
print(f"COLMAP KITTI retrieval (best verified earlier frame): {findable} queries could be found, "
      f"{closures} loop closures, {true} of them true")
