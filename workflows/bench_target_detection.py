"""OpenCV's chessboard detection and cornerSubPix on a folder, one thread:
the peer of portcal's target_extractor in bench_target_detection.sh.
Prints "<seconds> <views found> <corners>". Run with /usr/bin/python3
(Debian's cv2)."""
import glob
import os
import sys
import time

import cv2

folder, cols, rows = sys.argv[1], int(sys.argv[2]), int(sys.argv[3])
cv2.setNumThreads(1)
paths = sorted(p for p in glob.glob(os.path.join(folder, "**", "*"), recursive=True)
               if p.lower().endswith((".png", ".jpg", ".jpeg", ".tif", ".tiff", ".bmp")))
criteria = (cv2.TERM_CRITERIA_EPS + cv2.TERM_CRITERIA_MAX_ITER, 30, 0.001)
flags = cv2.CALIB_CB_ADAPTIVE_THRESH | cv2.CALIB_CB_NORMALIZE_IMAGE | cv2.CALIB_CB_FAST_CHECK
start = time.perf_counter()
found = corners = 0
for path in paths:
    gray = cv2.imread(path, cv2.IMREAD_GRAYSCALE)
    ok, points = cv2.findChessboardCorners(gray, (cols, rows), flags=flags)
    if ok:
        cv2.cornerSubPix(gray, points, (11, 11), (-1, -1), criteria)
        found += 1
        corners += len(points)
print(f"{time.perf_counter() - start:.2f} {found} {corners}")
