#!/usr/bin/python3
"""Writes a EuRoC flight log (as `patrolmap simulate` makes it) as a ROS 1 bag or a ROS 2 bag.

ROS 1 bags are written with Debian's rosbag Python API (python3-rosbag and the message packages); ROS 2
bags with sqlite3, in the layout rosbag2 writes (metadata.yaml, one .db3 file, CDR messages), since Debian 12
packages no rosbag2 writer.

Topics: /cam0/image_raw (Image, or CompressedImage on /cam0/image_raw/compressed), /cam0/camera_info,
/imu0 (Imu), /gps (NavSatFix), /odometry (Odometry of the body frame), /tf_static (cam0 and imu0 in the
body frame, from their sensor.yaml T_BS).

Usage: write_test_bags.py LOG OUT --format ros1|ros2 [--images raw|png|jpeg] [--encoding mono8|mono16|bgr8|
       rgb8|bgra8] [--chunks none|bz2|lz4] [--time-offset-s S]
"""
import argparse
import csv
import math
import os
import sqlite3
import struct

import cv2
import numpy as np
import yaml


def read_table(path):
    if not os.path.exists(path):
        return []
    with open(path) as f:
        return [row for row in csv.reader(f) if row and not row[0].startswith("#")]


def rotation_to_quaternion(m):
    """(x, y, z, w) of a 3x3 rotation matrix, computed as Eigen's Quaternion(Matrix3) does, operation for
    operation, so a reader that turns the quaternion back holds the same bits as one that reads the matrix."""
    m = [[float(v) for v in row] for row in np.asarray(m, dtype=float)]
    q = [0.0, 0.0, 0.0, 0.0]  # x, y, z, w
    t = m[0][0] + m[1][1] + m[2][2]
    if t > 0:
        t = math.sqrt(t + 1.0)
        q[3] = 0.5 * t
        t = 0.5 / t
        q[0] = (m[2][1] - m[1][2]) * t
        q[1] = (m[0][2] - m[2][0]) * t
        q[2] = (m[1][0] - m[0][1]) * t
    else:
        i = 1 if m[1][1] > m[0][0] else 0
        if m[2][2] > m[i][i]:
            i = 2
        j, k = (i + 1) % 3, (i + 2) % 3
        t = math.sqrt(m[i][i] - m[j][j] - m[k][k] + 1.0)
        q[i] = 0.5 * t
        t = 0.5 / t
        q[3] = (m[k][j] - m[j][k]) * t
        q[j] = (m[j][i] + m[i][j]) * t
        q[k] = (m[k][i] + m[i][k]) * t
    return tuple(q)


def sensor_transform(path):
    """(translation, quaternion xyzw) of a sensor.yaml's T_BS, identity when absent."""
    if not os.path.exists(path):
        return (0.0, 0.0, 0.0), (0.0, 0.0, 0.0, 1.0)
    data = yaml.safe_load(open(path)).get("T_BS", {}).get("data")
    if not data:
        return (0.0, 0.0, 0.0), (0.0, 0.0, 0.0, 1.0)
    m = np.array(data, dtype=float).reshape(4, 4)
    return tuple(m[:3, 3]), rotation_to_quaternion(m[:3, :3])


def image_payload(path, encoding):
    """(height, width, encoding, step, bytes) of an image file as a sensor_msgs/Image holds it."""
    grey = cv2.imread(path, cv2.IMREAD_GRAYSCALE)
    if encoding == "mono8":
        pixels = grey
    elif encoding == "mono16":
        pixels = grey.astype(np.uint16) * 256
    elif encoding == "bgr8":
        pixels = cv2.cvtColor(grey, cv2.COLOR_GRAY2BGR)
    elif encoding == "rgb8":
        pixels = cv2.cvtColor(grey, cv2.COLOR_GRAY2RGB)
    else:
        pixels = cv2.cvtColor(grey, cv2.COLOR_GRAY2BGRA)
    pixels = np.ascontiguousarray(pixels)
    return pixels.shape[0], pixels.shape[1], encoding, pixels.strides[0], pixels.tobytes()


def compressed_payload(path, image_format):
    grey = cv2.imread(path, cv2.IMREAD_GRAYSCALE)
    ok, data = cv2.imencode("." + ("jpg" if image_format == "jpeg" else "png"), grey,
                            [cv2.IMWRITE_JPEG_QUALITY, 95] if image_format == "jpeg" else [])
    assert ok
    return image_format, data.tobytes()


def flight_messages(log, images, encoding):
    """Every message of the log as (time_ns, topic, kind, fields), in time order."""
    root = os.path.join(log, "mav0") if os.path.isdir(os.path.join(log, "mav0")) else log
    messages = []
    camera_yaml = os.path.join(root, "cam0", "sensor.yaml")
    camera = yaml.safe_load(open(camera_yaml)) if os.path.exists(camera_yaml) else None
    camera_topic = "/cam0/image_raw" + ("" if images == "raw" else "/compressed")
    for row in read_table(os.path.join(root, "cam0", "data.csv")):
        t, name = int(row[0]), row[1].strip()
        path = os.path.join(root, "cam0", "data", name)
        if images == "raw":
            messages.append((t, camera_topic, "image", image_payload(path, encoding)))
        else:
            messages.append((t, camera_topic, "compressed", compressed_payload(path, images)))
        if camera:
            messages.append((t, "/cam0/camera_info", "camera_info", camera))
    for row in read_table(os.path.join(root, "depth0", "data.csv")):
        depth = cv2.imread(os.path.join(root, "depth0", "data", row[1].strip()), cv2.IMREAD_UNCHANGED)
        messages.append((int(row[0]), "/cam0/depth/image_raw", "depth",
                         (depth.shape[0], depth.shape[1], "16UC1", depth.strides[0], depth.tobytes())))
    right_yaml = os.path.join(root, "cam1", "sensor.yaml")
    if camera and os.path.exists(right_yaml):
        right = dict(yaml.safe_load(open(right_yaml)))
        right["baseline_m"] = baseline(camera_yaml, right_yaml)
        for row in read_table(os.path.join(root, "cam1", "data.csv")):
            t, path = int(row[0]), os.path.join(root, "cam1", "data", row[1].strip())
            if images == "raw":
                messages.append((t, "/cam1/image_raw", "image", image_payload(path, encoding)))
            else:
                messages.append((t, "/cam1/image_raw/compressed", "compressed", compressed_payload(path, images)))
            messages.append((t, "/cam1/camera_info", "camera_info", right))
    for row in read_table(os.path.join(root, "imu0", "data.csv")):
        messages.append((int(row[0]), "/imu0", "imu", [float(v) for v in row[1:7]]))
    for row in read_table(os.path.join(root, "gps0", "data.csv")):
        messages.append((int(row[0]), "/gps", "gps", [float(v) for v in row[1:4]]))
    for row in read_table(os.path.join(root, "state_groundtruth_estimate0", "data.csv")):
        messages.append((int(row[0]), "/odometry", "odometry", [float(v) for v in row[1:11]]))
    transforms = [("body", "cam0") + sensor_transform(camera_yaml),
                  ("body", "imu0") + sensor_transform(os.path.join(root, "imu0", "sensor.yaml"))]
    first = min(m[0] for m in messages)
    messages.append((first, "/tf_static", "tf", transforms))
    messages.sort(key=lambda m: (m[0], m[1] != "/tf_static"))
    return messages


def baseline(left_yaml, right_yaml):
    """The right camera's offset along the left camera's x axis [m] (both T_BS, cameras parallel)."""
    def transform(path):
        return np.array(yaml.safe_load(open(path))["T_BS"]["data"], dtype=float).reshape(4, 4)
    left, right = transform(left_yaml), transform(right_yaml)
    in_left = left[:3, :3].T @ (right[:3, 3] - left[:3, 3])
    return float(in_left[0])


# Messages are recorded a little after their header stamps, as on a real robot: readers must time frames by
# the stamps.
RECORD_DELAY_NS = 2_000_000

FRAME_OF = {"depth": "cam0", "image": "cam0", "compressed": "cam0", "camera_info": "cam0", "imu": "imu0", "gps": "gps",
            "odometry": "world"}

TYPES = {"depth": "sensor_msgs/Image", "image": "sensor_msgs/Image", "compressed": "sensor_msgs/CompressedImage",
         "camera_info": "sensor_msgs/CameraInfo", "imu": "sensor_msgs/Imu", "gps": "sensor_msgs/NavSatFix",
         "odometry": "nav_msgs/Odometry", "tf": "tf2_msgs/TFMessage"}


def camera_matrices(camera):
    fx, fy, cx, cy = camera["intrinsics"]
    k = [fx, 0, cx, 0, fy, cy, 0, 0, 1]
    r = [1, 0, 0, 0, 1, 0, 0, 0, 1]
    p = [fx, 0, cx, -fx * camera.get("baseline_m", 0.0), 0, fy, cy, 0, 0, 0, 1, 0]
    return k, r, p, [float(v) for v in camera.get("distortion_coefficients", [0, 0, 0, 0])]


# ---------------------------------------------------------------- ROS 1
def write_ros1(messages, out, chunks):
    import genpy
    import rosbag
    from geometry_msgs.msg import TransformStamped
    from nav_msgs.msg import Odometry
    from sensor_msgs.msg import CameraInfo, CompressedImage, Image, Imu, NavSatFix
    from tf2_msgs.msg import TFMessage

    def stamp(msg, t, kind):
        msg.header.stamp = genpy.Time(t // 1_000_000_000, t % 1_000_000_000)
        msg.header.frame_id = FRAME_OF.get(kind, "")

    with rosbag.Bag(out, "w", compression=chunks) as bag:
        for t, topic, kind, fields in messages:
            if kind in ("image", "depth"):
                msg = Image(height=fields[0], width=fields[1], encoding=fields[2], is_bigendian=0, step=fields[3],
                            data=fields[4])
            elif kind == "compressed":
                msg = CompressedImage(format=fields[0], data=fields[1])
            elif kind == "camera_info":
                k, r, p, d = camera_matrices(fields)
                msg = CameraInfo(width=fields["resolution"][0], height=fields["resolution"][1],
                                 distortion_model="plumb_bob", D=d, K=k, R=r, P=p)
            elif kind == "imu":
                msg = Imu()
                msg.orientation_covariance[0] = -1
                msg.angular_velocity.x, msg.angular_velocity.y, msg.angular_velocity.z = fields[0:3]
                msg.linear_acceleration.x, msg.linear_acceleration.y, msg.linear_acceleration.z = fields[3:6]
            elif kind == "gps":
                msg = NavSatFix(latitude=fields[0], longitude=fields[1], altitude=fields[2])
            elif kind == "odometry":
                msg = Odometry(child_frame_id="body")
                p, q, v = msg.pose.pose.position, msg.pose.pose.orientation, msg.twist.twist.linear
                p.x, p.y, p.z = fields[0:3]
                q.w, q.x, q.y, q.z = fields[3:7]
                v.x, v.y, v.z = fields[7:10]
            else:
                msg = TFMessage()
                for parent, child, translation, rotation in fields:
                    transform = TransformStamped()
                    transform.header.frame_id, transform.child_frame_id = parent, child
                    tr, ro = transform.transform.translation, transform.transform.rotation
                    tr.x, tr.y, tr.z = translation
                    ro.x, ro.y, ro.z, ro.w = rotation
                    msg.transforms.append(transform)
            if kind != "tf":
                stamp(msg, t, kind)
            recorded = t + RECORD_DELAY_NS
            bag.write(topic, msg, t=genpy.Time(recorded // 1_000_000_000, recorded % 1_000_000_000))


# ---------------------------------------------------------------- ROS 2 (CDR)
class Cdr:
    """Little-endian CDR as ROS 2 serialises messages: primitives aligned to their size after the header."""

    def __init__(self):
        self.data = bytearray(b"\x00\x01\x00\x00")

    def align(self, size):
        while (len(self.data) - 4) % size:
            self.data.append(0)

    def put(self, fmt, *values):
        self.align(struct.calcsize("<" + fmt[0]))
        self.data += struct.pack("<" + fmt, *values)

    def string(self, text):
        encoded = text.encode() + b"\x00"
        self.put("I", len(encoded))
        self.data += encoded

    def header(self, t, frame):
        self.put("iI", t // 1_000_000_000, t % 1_000_000_000)
        self.string(frame)

    def doubles(self, values):
        for value in values:
            self.put("d", value)

    def byte_sequence(self, data):
        self.put("I", len(data))
        self.data += data


def cdr_message(t, kind, fields):
    w = Cdr()
    if kind == "tf":
        w.put("I", len(fields))
        for parent, child, translation, rotation in fields:
            w.header(t, parent)
            w.string(child)
            w.doubles(translation)
            w.doubles(rotation)
        return bytes(w.data)
    w.header(t, FRAME_OF[kind])
    if kind in ("image", "depth"):
        height, width, encoding, step, data = fields
        w.put("I", height)
        w.put("I", width)
        w.string(encoding)
        w.put("B", 0)
        w.put("I", step)
        w.byte_sequence(data)
    elif kind == "compressed":
        w.string(fields[0])
        w.byte_sequence(fields[1])
    elif kind == "camera_info":
        k, r, p, d = camera_matrices(fields)
        w.put("I", fields["resolution"][1])
        w.put("I", fields["resolution"][0])
        w.string("plumb_bob")
        w.put("I", len(d))
        w.doubles(d)
        w.doubles(k)
        w.doubles(r)
        w.doubles(p)
        w.put("I", 0)
        w.put("I", 0)
        w.put("IIII", 0, 0, 0, 0)
        w.put("B", 0)
    elif kind == "imu":
        w.doubles([0, 0, 0, 1] + [-1] + [0] * 8)
        w.doubles(fields[0:3])
        w.doubles([0] * 9)
        w.doubles(fields[3:6])
        w.doubles([0] * 9)
    elif kind == "gps":
        w.put("b", 0)
        w.put("H", 1)
        w.doubles(fields[0:3])
        w.doubles([0] * 9)
        w.put("B", 0)
    elif kind == "odometry":
        w.string("body")
        w.doubles(fields[0:3])
        w.doubles([fields[4], fields[5], fields[6], fields[3]])
        w.doubles([0] * 36)
        w.doubles(fields[7:10])
        w.doubles([0, 0, 0])
        w.doubles([0] * 36)
    return bytes(w.data)


def ros2_type(kind):
    package, name = TYPES[kind].split("/")
    return package + "/msg/" + name


def write_ros2(messages, out):
    os.makedirs(out, exist_ok=True)
    name = os.path.basename(os.path.normpath(out)) + "_0.db3"
    database = sqlite3.connect(os.path.join(out, name))
    database.executescript("""
        CREATE TABLE schema(schema_version INTEGER PRIMARY KEY, ros_distro TEXT NOT NULL);
        INSERT INTO schema VALUES (3, 'humble');
        CREATE TABLE metadata(id INTEGER PRIMARY KEY, metadata_version INTEGER NOT NULL, metadata TEXT NOT NULL);
        CREATE TABLE topics(id INTEGER PRIMARY KEY, name TEXT NOT NULL, type TEXT NOT NULL,
                            serialization_format TEXT NOT NULL, offered_qos_profiles TEXT NOT NULL);
        CREATE TABLE messages(id INTEGER PRIMARY KEY, topic_id INTEGER NOT NULL, timestamp INTEGER NOT NULL,
                              data BLOB NOT NULL);
        CREATE INDEX timestamp_idx ON messages (timestamp ASC);""")
    topic_ids, counts = {}, {}
    for t, topic, kind, fields in messages:
        if topic not in topic_ids:
            topic_ids[topic] = len(topic_ids) + 1
            database.execute("INSERT INTO topics VALUES (?, ?, ?, 'cdr', '')", (topic_ids[topic], topic, ros2_type(kind)))
        counts[topic] = counts.get(topic, 0) + 1
        database.execute("INSERT INTO messages (topic_id, timestamp, data) VALUES (?, ?, ?)",
                         (topic_ids[topic], t + RECORD_DELAY_NS, cdr_message(t, kind, fields)))
    database.commit()
    database.close()
    kinds = {topic: kind for _, topic, kind, _ in messages}
    times = [m[0] for m in messages]
    metadata = {"rosbag2_bagfile_information": {
        "version": 5, "storage_identifier": "sqlite3", "relative_file_paths": [name],
        "duration": {"nanoseconds": max(times) - min(times)}, "starting_time": {"nanoseconds_since_epoch": min(times)},
        "message_count": len(messages),
        "topics_with_message_count": [
            {"topic_metadata": {"name": topic, "type": ros2_type(kinds[topic]), "serialization_format": "cdr",
                                "offered_qos_profiles": ""}, "message_count": counts[topic]}
            for topic in topic_ids],
        "compression_format": "", "compression_mode": ""}}
    with open(os.path.join(out, "metadata.yaml"), "w") as f:
        yaml.safe_dump(metadata, f, sort_keys=False)


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("log")
    parser.add_argument("out")
    parser.add_argument("--format", choices=["ros1", "ros2"], required=True)
    parser.add_argument("--images", choices=["raw", "png", "jpeg"], default="raw")
    parser.add_argument("--encoding", choices=["mono8", "mono16", "bgr8", "rgb8", "bgra8"], default="mono8")
    parser.add_argument("--chunks", choices=["none", "bz2", "lz4"], default="none")
    parser.add_argument("--time-offset-s", type=int, default=0,
                        help="added to every time (ROS 1 cannot store times at 0, where simulated logs start)")
    args = parser.parse_args()
    offset = args.time_offset_s * 1_000_000_000
    messages = [(t + offset, topic, kind, fields)
                for t, topic, kind, fields in flight_messages(args.log, args.images, args.encoding)]
    if args.format == "ros1":
        write_ros1(messages, args.out, args.chunks)
    else:
        write_ros2(messages, args.out)


if __name__ == "__main__":
    main()
