#!/usr/bin/env python3
"""Runs a command and samples its memory and CPU once a second (BENCHMARKS.md: long onboard replays).

    scripts/rss_sample.py --out PREFIX [--every S] -- COMMAND [ARGS...]

Writes PREFIX.csv (elapsed_s, rss_mb, cpu_percent: the command's share of one core over the last sample)
and PREFIX.svg (resident memory over time), and prints the peak, the mean CPU share and the command's exit
code. Linux only (/proc); the Python standard library only.
"""
import argparse
import os
import subprocess
import sys
import time


def rss_mb(pid):
    try:
        with open(f"/proc/{pid}/status") as status:
            for line in status:
                if line.startswith("VmRSS:"):
                    return int(line.split()[1]) / 1024.0
    except OSError:
        pass
    return None


def cpu_seconds(pid):
    try:
        with open(f"/proc/{pid}/stat") as stat:
            fields = stat.read().rsplit(")", 1)[1].split()
        return (int(fields[11]) + int(fields[12])) / os.sysconf("SC_CLK_TCK")  # utime + stime
    except (OSError, IndexError, ValueError):
        return None


def plot(samples, path, title):
    width, height, margin = 720, 300, 50
    end = max(s[0] for s in samples) or 1.0
    top = max(s[1] for s in samples) * 1.1 or 1.0
    x = lambda t: margin + (width - 2 * margin) * t / end
    y = lambda mb: height - margin - (height - 2 * margin) * mb / top
    points = " ".join(f"{x(t):.1f},{y(mb):.1f}" for t, mb, _ in samples)
    ticks = []
    for i in range(5):
        mb = top * i / 4
        ticks.append(f'<text x="{margin - 6}" y="{y(mb) + 4:.1f}" text-anchor="end">{mb:.0f}</text>')
        t = end * i / 4
        ticks.append(f'<text x="{x(t):.1f}" y="{height - margin + 16}" text-anchor="middle">{t / 60:.1f}</text>')
    svg = f"""<svg xmlns="http://www.w3.org/2000/svg" width="{width}" height="{height}" font-family="sans-serif" font-size="11">
<text x="{width / 2}" y="18" text-anchor="middle" font-size="13">{title}</text>
<line x1="{margin}" y1="{height - margin}" x2="{width - margin}" y2="{height - margin}" stroke="black"/>
<line x1="{margin}" y1="{margin}" x2="{margin}" y2="{height - margin}" stroke="black"/>
{"".join(ticks)}
<text x="{width / 2}" y="{height - 12}" text-anchor="middle">minutes</text>
<text x="14" y="{height / 2}" transform="rotate(-90 14 {height / 2})" text-anchor="middle">resident memory [MB]</text>
<polyline fill="none" stroke="#1f77b4" stroke-width="1.5" points="{points}"/>
</svg>
"""
    with open(path, "w") as out:
        out.write(svg)


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--out", required=True, help="prefix of the CSV and SVG written")
    parser.add_argument("--every", type=float, default=1.0, help="seconds between samples")
    parser.add_argument("command", nargs=argparse.REMAINDER)
    args = parser.parse_args()
    command = args.command[1:] if args.command[:1] == ["--"] else args.command
    if not command:
        parser.error("no command given")
    start = time.monotonic()
    process = subprocess.Popen(command)
    samples = []
    last_cpu, last_t = 0.0, 0.0
    while process.poll() is None:
        time.sleep(args.every)
        t = time.monotonic() - start
        mb, cpu = rss_mb(process.pid), cpu_seconds(process.pid)
        if mb is None or cpu is None:
            continue
        share = 100.0 * (cpu - last_cpu) / (t - last_t) if t > last_t else 0.0
        samples.append((t, mb, share))
        last_cpu, last_t = cpu, t
    code = process.wait()
    with open(args.out + ".csv", "w") as out:
        out.write("elapsed_s,rss_mb,cpu_percent\n")
        out.writelines(f"{t:.1f},{mb:.1f},{share:.0f}\n" for t, mb, share in samples)
    if samples:
        plot(samples, args.out + ".svg", "resident memory of " + os.path.basename(command[0]))
        peak = max(s[1] for s in samples)
        mean_cpu = sum(s[2] for s in samples) / len(samples)
        print(f"{len(samples)} samples over {samples[-1][0]:.0f} s: peak {peak:.0f} MB, "
              f"mean CPU {mean_cpu:.0f} % of one core; exit code {code}")
    return code


if __name__ == "__main__":
    sys.exit(main())
