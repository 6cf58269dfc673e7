#!/usr/bin/python3
"""Attacks patrolmap's release binaries with malformed input and tells how each attempt ended.

    scripts/attack/attack.py BIN_DIR [--out DIR] [--quick]

BIN_DIR holds `patrolmap` and `patrolmap-onboard` (e.g. build/tools). A small simulated log and its map
are made first; then every family of inputs below is damaged in many ways, each damaged input is given to
the command that reads it, and the outcome is classified:

  clear error   non-zero exit, and stderr names the damaged file (or the option) -- what we want
  warning       exit 0 and stderr warns (damaged but usable input, used)
  loaded        exit 0 on damage that leaves a valid input (a flipped pixel behind a recomputed checksum)
  unclear       non-zero exit without naming the file or option
  silent        exit 0 without a warning on input that is invalid -- a defect
  crash         killed by a signal (or the sanitizer's exit code 1 with a report) -- a defect
  hang          no exit within the time limit -- a defect
  data loss     an input file changed or vanished -- a defect
  injection     hostile text reached an output unescaped -- a defect

Prints one Markdown table (ROBUSTNESS.md keeps the latest) and writes the failing inputs under OUT.
Standard library only (Debian's python3).
"""
import argparse
import hashlib
import math
import os
import random
import re
import shutil
import struct
import subprocess
import sys
import tempfile
import time
from collections import Counter, OrderedDict
from pathlib import Path

CHECKSUM_SEED = 0x9E3779B97F4A7C15
MASK = (1 << 64) - 1
OUTCOMES = ["clear error", "warning", "loaded", "unclear", "silent", "crash", "hang", "data loss", "injection"]


def checksum(data, h=CHECKSUM_SEED):
    """patrolmap's section checksum (src/core/checksum.cc)."""
    h ^= len(data)
    i = 0
    while i + 8 <= len(data):
        (word,) = struct.unpack_from("<Q", data, i)
        h = ((h ^ word) * 0xFF51AFD7ED558CCD) & MASK
        h ^= h >> 29
        i += 8
    for b in data[i:]:
        h = ((h ^ b) * 0x100000001B3) & MASK
    return h


def recompute_map_checksums(data):
    data = bytearray(data)
    pos = 16
    while pos + 20 <= len(data):
        (length,) = struct.unpack_from("<Q", data, pos + 4)
        if length > len(data) - pos - 20:
            break
        struct.pack_into("<Q", data, pos + 12, checksum(bytes(data[pos + 20 : pos + 20 + length])))
        pos += 20 + length
    return bytes(data)


def digest(path):
    p = Path(path)
    if p.is_dir():
        h = hashlib.sha256()
        for f in sorted(p.rglob("*")):
            if f.is_file():
                h.update(str(f.relative_to(p)).encode())
                h.update(f.read_bytes())
        return h.hexdigest()
    return hashlib.sha256(p.read_bytes()).hexdigest() if p.exists() else None


class Attack:
    def __init__(self, bin_dir, out, timeout):
        self.patrolmap = str(Path(bin_dir) / "patrolmap")
        self.onboard = str(Path(bin_dir) / "patrolmap-onboard")
        self.out = Path(out)
        self.timeout = timeout
        self.rows = OrderedDict()
        self.failures = self.out / "failures"
        self.failures.mkdir(parents=True, exist_ok=True)
        self.count = 0
        self.known_warnings = set()

    def run(self, args, cwd=None):
        try:
            p = subprocess.run(args, capture_output=True, timeout=self.timeout, cwd=cwd)
            return p.returncode, p.stderr.decode(errors="replace") + p.stdout.decode(errors="replace")
        except subprocess.TimeoutExpired:
            return None, ""

    def record(self, family, outcome, detail, keep=None):
        row = self.rows.setdefault(family, Counter())
        row[outcome] += 1
        self.count += 1
        if outcome in ("unclear", "silent", "crash", "hang", "data loss", "injection"):
            print(f"  {outcome}: {family}: {detail}", file=sys.stderr)
            if keep is not None and Path(keep).exists():
                target = self.failures / f"{len(list(self.failures.iterdir()))}-{Path(keep).name}"
                (shutil.copytree if Path(keep).is_dir() else shutil.copy)(keep, target)

    def baseline(self, args):
        """The warnings a command prints on undamaged input: only new ones count as warnings."""
        code, text = self.run(args)
        self.known_warnings |= {self.normalise(l) for l in text.splitlines() if "warn" in l}

    @staticmethod
    def normalise(line):
        return line.split("] ", 2)[-1] if line.startswith("[") else line

    def judge(self, family, args, names, invalid=True, keep=None, guarded=()):
        """Runs `args`; `names` are strings an error must mention (any one); `guarded` files must not change."""
        before = {g: digest(g) for g in guarded}
        code, text = self.run(args)
        changed = [g for g in guarded if digest(g) != before[g]]
        sanitizer = "Sanitizer" in text or "runtime error:" in text
        if changed:
            outcome = "data loss"
        elif code is None:
            outcome = "hang"
        elif code < 0 or code >= 128 or sanitizer or "terminate called" in text or "check failed" in text:
            outcome = "crash"
        elif code != 0:
            outcome = "clear error" if any(n in text for n in names) else "unclear"
        elif any("warn" in l and self.normalise(l) not in self.known_warnings for l in text.splitlines()):
            outcome = "warning"
        else:
            outcome = "silent" if invalid else "loaded"
        self.record(family, outcome, " ".join(map(str, args))[:300] + " -> " + text.strip()[-300:], keep)
        return outcome

    def table(self):
        lines = ["| input family | tried | " + " | ".join(OUTCOMES) + " |",
                 "|---|---:|" + "---:|" * len(OUTCOMES)]
        total = Counter()
        for family, row in self.rows.items():
            total.update(row)
            lines.append(f"| {family} | {sum(row.values())} | " + " | ".join(str(row[o]) for o in OUTCOMES) + " |")
        lines.append(f"| **all** | **{sum(total.values())}** | " + " | ".join(f"**{total[o]}**" for o in OUTCOMES) + " |")
        return "\n".join(lines)


def make_log(attack, work):
    log = work / "log"
    code, text = attack.run([attack.patrolmap, "simulate", "--route", "street", "--resolution", "188x120",
                             "--speed", "3", "--walls", "2", "--detections", "--depth", "--gps", "--out", str(log)])
    if code != 0:
        sys.exit("cannot simulate the test log: " + text)
    code, text = attack.run([attack.patrolmap, "map", str(log), "--out", str(work / "mapped")])
    if code != 0:
        sys.exit("cannot map the test log: " + text)
    for command in ["map", "detect"]:
        attack.baseline([attack.patrolmap, command, str(log), "--out", str(work / "baseline")])
    return log, work / "mapped" / "map.pmap"


def attack_map_files(attack, work, prior, rng, n):
    data = prior.read_bytes()
    bad = work / "bad.pmap"
    for i in range(n):
        bad.write_bytes(data[: len(data) * i // n])
        attack.judge("map file: truncated", [attack.patrolmap, "info", str(bad)], [str(bad)], keep=bad)
    for _ in range(n):
        flipped = bytearray(data)
        bit = rng.randrange(8 * len(data))
        flipped[bit // 8] ^= 1 << (bit % 8)
        bad.write_bytes(flipped)
        attack.judge("map file: bit flip", [attack.patrolmap, "info", str(bad)], [str(bad)], keep=bad)
    # Behind recomputed checksums the damage reaches the parsers; a flip inside a pixel or descriptor
    # leaves a valid map ("loaded"), anything impossible must be refused.
    for _ in range(n):
        flipped = bytearray(data)
        bit = rng.randrange(8 * len(data))
        flipped[bit // 8] ^= 1 << (bit % 8)
        bad.write_bytes(recompute_map_checksums(bytes(flipped)))
        out = work / "export.html"
        attack.judge("map file: bit flip, checksums recomputed, export html",
                     [attack.patrolmap, "export", str(bad), "--format", "html", "--out", str(out)], [str(bad)],
                     invalid=False, keep=bad)


def attack_vocabulary(attack, work, log, vocabulary, rng, n):
    data = Path(vocabulary).read_bytes()
    bad = work / "bad.pmvoc"
    for i in range(n):
        cut = rng.randrange(len(data))
        bad.write_bytes(data[:cut])
        attack.judge("vocabulary: truncated", [attack.patrolmap, "map", str(log), "--vocabulary", str(bad),
                                               "--out", str(work / "vout")], [str(bad)], keep=bad)
    for _ in range(n):
        flipped = bytearray(data)
        bit = rng.randrange(8 * len(data))
        flipped[bit // 8] ^= 1 << (bit % 8)
        bad.write_bytes(flipped)
        attack.judge("vocabulary: bit flip", [attack.patrolmap, "map", str(log), "--vocabulary", str(bad),
                                              "--out", str(work / "vout")], [str(bad)], keep=bad)


def numeric_keys(default_yaml):
    """(dotted key, line index) of every numeric value in the default configuration."""
    keys, stack = [], []
    lines = Path(default_yaml).read_text().splitlines()
    for index, line in enumerate(lines):
        body = line.split("#")[0].rstrip()
        if not body.strip() or ":" not in body:
            continue
        indent = len(body) - len(body.lstrip())
        key, _, value = body.strip().partition(":")
        while stack and stack[-1][0] >= indent:
            stack.pop()
        if not value.strip():
            stack.append((indent, key))
            continue
        try:
            float(value.strip())
        except ValueError:
            continue
        keys.append((".".join([k for _, k in stack] + [key]), index))
    return keys, lines


def attack_config(attack, work, log, default_yaml, quick):
    keys, lines = numeric_keys(default_yaml)
    values = ["nan", ".inf", "-.inf", "1e300", "-1e300", "text"] if not quick else ["nan", "1e300"]
    bad = work / "bad.yaml"
    for key, index in keys:
        for value in values:
            changed = list(lines)
            head = changed[index].split(":")[0]
            changed[index] = f"{head}: {value}"
            bad.write_text("\n".join(changed) + "\n")
            attack.judge("configuration: one value NaN, inf, huge or text",
                         [attack.patrolmap, "detect", str(log), "--config", str(bad),
                          "--out", str(work / "cout")], [key.split(".")[-1]], keep=bad)
    for name, text in [("duplicate key", "flow:\n  frames:\n    rate_hz: 6\n    rate_hz: 7\n"),
                       ("unknown key", "flow:\n  frames:\n    rate: 6\n"),
                       ("scalar document", "42\n"), ("list document", "- a\n- b\n"),
                       ("tab indentation", "flow:\n\tframes: 1\n"), ("binary", "\x00\x01\x02\xff")]:
        bad.write_text(text)
        outcome = attack.judge("configuration: malformed document", [attack.patrolmap, "detect", str(log), "--config",
                                                           str(bad), "--out", str(work / "cout")], [str(bad)],
                     keep=bad)
        if outcome == "silent":
            print(f"    ({name})", file=sys.stderr)


TABLES = {"cam0/data.csv": True, "imu0/data.csv": True, "state_groundtruth_estimate0/data.csv": True,
          "gps0/data.csv": True, "objects0/data.csv": False, "depth0/data.csv": True}


def table_damage(rows, rng, strict):
    """Damaged variants of a CSV table's rows (header kept): each is invalid for every table."""
    data = [i for i, r in enumerate(rows) if r and not r.startswith("#")]
    if len(data) < 3:
        return OrderedDict()
    k = rng.choice(data[1:-1])
    fields = rows[k].split(",")
    variants = OrderedDict()
    for name, value in [("NaN", "nan"), ("inf", "inf"), ("text", "abc"), ("empty", "")]:
        column = rng.randrange(1, len(fields)) if len(fields) > 1 else 0
        if rows[0].startswith("#") and "filename" in rows[0] and column == 1 and name != "empty":
            continue  # a file name may be any text
        changed = list(fields)
        changed[column] = value
        variants[f"{name} field"] = rows[:k] + [",".join(changed)] + rows[k + 1 :]
    variants["missing column"] = rows[:k] + [",".join(fields[:1])] + rows[k + 1 :]
    t = int(fields[0])
    variants["time going back"] = rows[:k] + [",".join([str(t - 10**10)] + fields[1:])] + rows[k + 1 :]
    variants["time beyond 2^62 ns"] = rows[:k] + [",".join(["9223372036854775807"] + fields[1:])] + rows[k + 1 :]
    variants["negative time"] = rows[:k] + [",".join(["-1"] + fields[1:])] + rows[k + 1 :]
    if strict:
        variants["repeated row"] = rows[: k + 1] + [rows[k]] + rows[k + 1 :]
    variants["cut mid-row"] = rows[:k] + [rows[k][: len(rows[k]) // 2]]
    return variants


def attack_tables(attack, work, log, rng, rounds):
    for table, strict in TABLES.items():
        original = (log / table).read_text()
        rows = original.splitlines()
        for _ in range(rounds):
            for name, variant in table_damage(rows, rng, strict).items():
                (log / table).write_text("\n".join(variant) + "\n")
                family = f"EuRoC table: {table.split('/')[0]}"
                outcome = attack.judge(family, [attack.patrolmap, "map", str(log), "--out",
                                                str(work / "tout")], [table], keep=log / table)
                if outcome == "silent":
                    print(f"    ({name})", file=sys.stderr)
        (log / table).write_text(original)


def attack_yaml(attack, work, log):
    """Each file gets the shapes every YAML file must survive, and bad values of the keys patrolmap reads
    from it (keys it does not read, such as an IMU's noise figures, are not its business)."""
    t_bs = ["T_BS: 5\n", "T_BS:\n  rows: 4\n  cols: 4\n  data: [.nan, 0, 0]\n",
            "T_BS:\n  rows: 4\n  cols: 4\n  data: [.nan, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1]\n",
            "T_BS:\n  rows: 4\n  cols: 4\n  data: [0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0]\n",
            "T_BS:\n  rows: 4\n  cols: 4\n  data: [-1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1]\n"]
    read = {"cam0/sensor.yaml": t_bs + ["intrinsics: [-1, -1, 1, 1]\nresolution: [188, 120]\n",
                                        "intrinsics: [100, 100, 94, 60]\nresolution: [640, 480]\n",
                                        "intrinsics: [1, 1, 1, 1]\nresolution: [0, 0]\n", "rate_hz: .nan\n",
                                        "rate_hz: -5\n", "rate_hz: [1]\n"],
            "imu0/sensor.yaml": t_bs,
            "meta.yaml": ["flight_id: [a\n", "flight_id: {a: 1}\n", "frame_rate_hz: .nan\n",
                          "frame_rate_hz: -5\n"]}
    for yaml_file, values in read.items():
        original = (log / yaml_file).read_text()
        lines = original.splitlines()
        repeated = "\n".join(lines + lines[-1:]) + "\n"  # the last key twice
        for text in ["42\n", "- a\n- b\n", "\x00\xff\xfe", repeated] + values:
            (log / yaml_file).write_text(text, errors="surrogateescape")
            attack.judge(f"YAML: {yaml_file}", [attack.patrolmap, "map", str(log), "--out",
                                                str(work / "yout")], [yaml_file], keep=log / yaml_file)
        (log / yaml_file).write_text(original)


def attack_reported(attack, work, log, prior):
    """Inputs an independent attack found silent or slow: detections whose centroid lost a value, a compressed
    ROS 2 bag, a route far beyond any village, and a save interrupted by a signal."""
    table = log / "objects0/data.csv"
    original = table.read_text()
    rows = [line for line in original.splitlines() if line and not line.startswith("#")]
    for cut in (1, 2):
        fields = rows[0].split(",")
        damaged = ",".join(fields[: len(fields) - cut] if len(fields) >= 10 else fields[:7] + ["0.5"] * (3 - cut))
        table.write_text("\n".join([damaged] + rows[1:]) + "\n")
        attack.judge("reported: objects0 centroid cut short", [attack.patrolmap, "map", str(log), "--out",
                                                               str(work / "rout")], ["objects0/data.csv"], keep=table)
    table.write_text(original)
    bag = work / "compressed_ros2"
    code, _ = attack.run(["/usr/bin/python3", str(Path(__file__).resolve().parents[2] / "tests/write_test_bags.py"),
                          str(log), str(bag), "--format", "ros2"])
    if code == 0:
        metadata = bag / "metadata.yaml"
        metadata.write_text(re.sub(r"compression_format: [^\n]*", "compression_format: zstd", metadata.read_text()))
        attack.judge("reported: compressed ROS 2 bag", [attack.patrolmap, "map", str(bag), "--out",
                                                        str(work / "rout")], ["compression_format"])
    # Route frames whose JPEG headers state 8192 x 8192 pixels (a few kB each): every decode would allocate and
    # describe 67 Mpx; the map is refused as larger than its camera could have kept.
    data = bytearray(prior.read_bytes())
    for sof in (b"\xff\xc0\x00\x0b\x08", b"\xff\xc0\x00\x11\x08"):  # baseline frame headers, grey and colour
        at = data.find(sof)
        while at >= 0:
            data[at + 5:at + 9] = b"\x20\x00\x20\x00"
            at = data.find(sof, at + 9)
    huge = work / "huge_route.pmap"
    huge.write_bytes(recompute_map_checksums(bytes(data)))
    attack.judge("reported: route frames declaring 8192x8192", [attack.patrolmap, "diff", str(huge), "--out",
                                                                 str(work / "rdiff")], [str(huge)], keep=huge)
    route = work / "far.csv"
    for rows_text in ("0,0\n1e9,0\n", "0,0\n9000,0\n" * 5):
        route.write_text(rows_text)
        attack.judge("reported: simulated route beyond the village", [attack.patrolmap, "simulate", "--route",
                                                                      str(route), "--out", str(work / "rsim")],
                     [str(route)])
    # A merge stopped by SIGTERM at some point of its run (about 0.35 s for this map) leaves no temporary; the
    # deterministic case is core_test's AtomicFile.ASignalWhileWritingRemovesTheTemporary.
    out = work / "merged"
    for delay in (0.05, 0.1, 0.15, 0.2, 0.25, 0.3, 0.35):
        shutil.rmtree(out, ignore_errors=True)
        process = subprocess.Popen([attack.patrolmap, "-q", "merge", str(prior), str(prior), "--rename-clashes",
                                    "--out", str(out)], stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
        time.sleep(delay)
        process.terminate()
        process.wait()
        left = sorted(str(p.name) for p in out.glob("*.tmp.*")) if out.exists() else []
        attack.record("reported: merge stopped by SIGTERM", "data loss" if left else "clear error",
                      f"after {delay} s: {left}")


def attack_images(attack, work, log, rng, rounds):
    images = sorted((log / "cam0/data").iterdir(), key=lambda path: int(path.stem))
    for _ in range(rounds):
        # A frame the one pass reads: the flow stage decodes every 5th frame of the 30 Hz log (flow.frames.rate_hz
        # 6). The others are never decoded, so their damage cannot matter, and nothing is said of it.
        target = rng.choice(images[5:-1:5])
        original = target.read_bytes()
        for name, data in [("empty", b""), ("truncated", original[: len(original) // 3]),
                           ("garbage", os.urandom(500)), ("text", b"not an image")]:
            target.write_bytes(data)
            attack.judge("images: one frame damaged", [attack.patrolmap, "map", str(log), "--out",
                                                       str(work / "iout")], ["frame", target.name],
                         keep=target)
        target.write_bytes(original)
    folder = work / "unreadable"
    folder.mkdir(exist_ok=True)
    for i in range(5):
        (folder / f"{i:04d}.png").write_bytes(b"garbage")
    for extra in ([], ["--every-frame"]):
        attack.judge("images: a folder of unreadable images", [attack.patrolmap, "map", str(folder), "--out",
                                                               str(work / "uout")] + extra, [str(folder)])


def attack_bags(attack, work, log, rng, rounds):
    """ROS 1 and ROS 2 bags of the log, truncated, with flipped bytes, with damaged messages."""
    writer = Path(__file__).resolve().parents[2] / "tests" / "write_test_bags.py"
    python = "/usr/bin/python3"
    ros1, ros2 = work / "flight.bag", work / "flight_ros2"
    for args in ([str(log), str(ros1), "--format", "ros1", "--chunks", "lz4", "--time-offset-s", "1700000000"],
                 [str(log), str(ros2), "--format", "ros2"]):
        code, text = attack.run([python, str(writer)] + args)
        if code != 0:
            print("  bags skipped: the writer needs python3-rosbag (scripts/install_deps.sh): " + text[-200:],
                  file=sys.stderr)
            return
    original = ros1.read_bytes()
    bad = work / "bad.bag"
    for _ in range(rounds * 5):
        bad.write_bytes(original[: rng.randrange(0, len(original))])
        attack.judge("bags: ROS 1 truncated", [attack.patrolmap, "map", str(bad), "--out", str(work / "bout")],
                     [str(bad)], keep=bad)
    for _ in range(rounds * 5):
        data = bytearray(original)
        for _ in range(rng.randrange(1, 20)):
            data[rng.randrange(0, len(data))] = rng.randrange(256)
        bad.write_bytes(bytes(data))
        # Flipped pixels read as other pixels: loading without a word is right for them.
        attack.judge("bags: ROS 1 bytes flipped", [attack.patrolmap, "map", str(bad), "--out", str(work / "bout")],
                     [str(bad)], invalid=False, keep=bad)
    database = next(ros2.glob("*.db3"))
    pristine = database.read_bytes()
    for _ in range(rounds * 5):
        database.write_bytes(pristine[: rng.randrange(0, len(pristine))])
        attack.judge("bags: ROS 2 database truncated", [attack.patrolmap, "map", str(ros2), "--out",
                                                        str(work / "bout")], [str(database)], keep=ros2)
    import sqlite3
    for _ in range(rounds * 5):
        database.write_bytes(pristine)
        connection = sqlite3.connect(str(database))
        rows = connection.execute("SELECT id, data FROM messages ORDER BY RANDOM() LIMIT 5").fetchall()
        for row_id, blob in rows:
            damaged = blob[: rng.randrange(0, len(blob))] if rng.random() < 0.5 else os.urandom(rng.randrange(0, 64))
            connection.execute("UPDATE messages SET data = ? WHERE id = ?", (damaged, row_id))
        connection.commit()
        connection.close()
        attack.judge("bags: ROS 2 messages damaged", [attack.patrolmap, "map", str(ros2), "--out",
                                                      str(work / "bout")], [str(ros2), "topic"], keep=ros2)
    database.write_bytes(pristine)
    for role in ["camera=/nope", "camera=/imu0", "imu=/cam0/image_raw", "lidar=/x", "camera", "pose=/gps"]:
        attack.judge("bags: topic choice", [attack.patrolmap, "map", str(ros1), "--topic", role, "--out",
                                            str(work / "bout")], [str(ros1), "--topic", "role"])


def attack_video(attack, work, log):
    video = work / "clip.avi"
    if not shutil.which("ffmpeg"):
        print("  (no ffmpeg: video family skipped; scripts/install_deps.sh ffmpeg)", file=sys.stderr)
        return
    code, text = attack.run(["ffmpeg", "-y", "-loglevel", "error", "-framerate", "30", "-pattern_type", "glob",
                             "-i", str(log / "cam0/data/*.png"), "-c:v", "mjpeg", str(video)])
    if code != 0:
        sys.exit("ffmpeg cannot make the test video: " + text)
    data = video.read_bytes()
    for fraction in [0.2, 0.5, 0.8, 0.95]:
        cut = work / f"cut{int(fraction * 100)}.avi"
        cut.write_bytes(data[: int(len(data) * fraction)])
        attack.judge("video: truncated", [attack.patrolmap, "map", str(cut), "--out", str(work / "vidout")],
                     [cut.name], keep=cut)
    junk = work / "junk.mp4"
    junk.write_bytes(os.urandom(4000))
    attack.judge("video: garbage", [attack.patrolmap, "map", str(junk), "--out", str(work / "vidout")],
                 [junk.name])


def attack_options(attack, work, log, prior):
    p, o = attack.patrolmap, attack.onboard
    # (command before the value, option, values that are valid for it)
    small = ["--route", "l-shape", "--resolution", "94x60", "--speed", "8"]
    cases = [([p, "map", str(log), "--out", str(work / "oout")], "--fps", set()),
             ([p, "simulate", "--out", str(work / "osim")], "--speed", set()),
             ([p, "simulate", "--out", str(work / "osim")] + small, "--altitude", set()),
             ([p, "simulate", "--out", str(work / "osim")] + small, "--turn-radius", set()),
             ([p, "simulate", "--out", str(work / "osim")] + small, "--motion-blur", {"0"}),
             ([p, "eval", str(work / "mapped"), "--log", str(log)], "--tolerance", {"0"}),
             ([o, str(log), "--fast", "--out", str(work / "oon")], "--ring-s", set()),
             ([o, str(log), "--fast", "--out", str(work / "oon")], "--max-seconds", {"0", "1e300"}),
             ([o, str(log), "--fast", "--out", str(work / "oon")], "--queue", set()),
             ([o, str(log), "--fast", "--out", str(work / "oon")], "--fps", set())]
    for command, option, valid in cases:
        for value in ["nan", "inf", "-1", "0", "1e300", "abc"]:
            attack.judge("command-line options: out of range", command + [option, value], [option],
                         invalid=value not in valid)
    for pattern in ["lit%%.png", "frame_%n.png", "frame_%s.png", "frame_%d%d.png", "frame_%999999999d.png"]:
        attack.judge("command-line: printf patterns", [p, "detect", str(work / pattern), "--out",
                                                       str(work / "pout")], ["pattern", pattern, "no such"])


def attack_outputs(attack, work, log, prior):
    """Outputs aimed at inputs: each must be refused, and no input may change."""
    copy = work / "outputs"
    if copy.exists():
        shutil.rmtree(copy)
    shutil.copytree(prior.parent, copy)
    pmap = copy / "map.pmap"
    guarded = [str(pmap), str(log)]
    cases = [[attack.patrolmap, "export", str(pmap), "--format", "json", "--out", str(pmap)],
             [attack.patrolmap, "export", str(pmap), "--format", "html", "--out", str(copy / "." / "map.pmap")],
             [attack.patrolmap, "patrol", str(log), "--map", str(pmap), "--out", str(log)],
             [attack.patrolmap, "patrol", str(log), "--map", str(pmap), "--out", str(copy)],
             [attack.patrolmap, "detect", str(log), "--out", str(log)],
             [attack.patrolmap, "map", str(log), "--out", str(log)],
             [attack.onboard, str(log), "--map", str(pmap), "--fast", "--out", str(log)]]
    for args in cases:
        attack.judge("outputs onto inputs", args, ["input", "refus", "would overwrite", str(pmap), str(log)],
                     guarded=guarded)


def attack_injection(attack, work, log):
    """Flight ids (meta.yaml) made to break out of every text format: outputs must hold them escaped."""
    hostile = ['x</script><img src=x onerror=alert(1)>', 'a,b\nc', '"><svg onload=alert(1)>', "']]></x>&amp;"]
    for name in hostile:
        copy = work / "hostile_log"
        if copy.exists():
            shutil.rmtree(copy)
        shutil.copytree(log, copy)
        meta = copy / "meta.yaml"
        kept = [l for l in meta.read_text().splitlines() if not l.startswith("flight_id")]
        escaped = name.replace("\\", "\\\\").replace('"', '\\"').replace("\n", "\\n")
        meta.write_text("\n".join(kept + [f'flight_id: "{escaped}"']) + "\n")
        out = work / "hostile_out"
        code, text = attack.run([attack.patrolmap, "map", str(copy), "--out", str(out)])
        if code != 0:
            attack.record("hostile flight ids in every export", "unclear", f"map: {name!r}: {text[-300:]}")
            continue
        nodes = (out / "nodes.csv").read_text(errors="replace")
        for fmt in ["html", "svg", "graphml", "kml", "geojson", "json", "dot"]:
            target = work / f"hostile.{fmt}"
            code, text = attack.run([attack.patrolmap, "export", str(out / "map.pmap"), "--format", fmt,
                                     "--out", str(target)])
            written = target.read_text(errors="replace") if target.exists() else ""
            markup = fmt in ("html", "svg", "graphml", "kml")
            raw = markup and any(s in written for s in ["<img src=x", "<svg onload", "</script><", "]]></x>"])
            outcome = "injection" if raw or "a,b\nc" in nodes else ("loaded" if code == 0 else "unclear")
            attack.record("hostile flight ids in every export", outcome, f"{fmt}: {name!r}")


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("bin_dir")
    parser.add_argument("--out", default=None)
    parser.add_argument("--quick", action="store_true", help="fewer inputs per family (a smoke run)")
    parser.add_argument("--timeout", type=float, default=120.0)
    parser.add_argument("--seed", type=int, default=18)
    args = parser.parse_args()
    root = Path(__file__).resolve().parents[2]
    out = Path(args.out or tempfile.mkdtemp(prefix="patrolmap_attack_"))
    attack = Attack(args.bin_dir, out, args.timeout)
    rng = random.Random(args.seed)
    n = 12 if args.quick else 60
    work = out / "work"
    work.mkdir(parents=True, exist_ok=True)
    log, prior = make_log(attack, work)
    steps = [lambda: attack_map_files(attack, work, prior, rng, n),
             lambda: attack_vocabulary(attack, work, log, root / "vocab/default.pmvoc", rng, n // 3),
             lambda: attack_config(attack, work, log, root / "config/default.yaml", args.quick),
             lambda: attack_tables(attack, work, log, rng, 1 if args.quick else 3),
             lambda: attack_yaml(attack, work, log),
             lambda: attack_images(attack, work, log, rng, 1 if args.quick else 3),
             lambda: attack_video(attack, work, log),
             lambda: attack_bags(attack, work, log, rng, 1 if args.quick else 3),
             lambda: attack_options(attack, work, log, prior),
             lambda: attack_outputs(attack, work, log, prior),
             lambda: attack_injection(attack, work, log),
             lambda: attack_reported(attack, work, log, prior)]
    for step in steps:
        step()
        print(f"  {attack.count} inputs so far", file=sys.stderr)
    table = attack.table()
    (out / "robustness.md").write_text(table + "\n")
    print(table)
    print(f"\nfailing inputs, if any: {attack.failures}", file=sys.stderr)


if __name__ == "__main__":
    main()
