#include "bag_messages.h"

#include <algorithm>
#include <cmath>
#include <cstring>

namespace patrolmap::io::rosmsg {
namespace {

// Longest string or sequence a message field may declare before it is taken for damage: no flight-log
// message holds more than its own bytes, and the reader checks that too.
constexpr std::uint32_t kMaxStringBytes = 1 << 16;

// Reads fields in order from a message's bytes. CDR aligns each primitive to its size, counted from the
// end of the 4-byte encapsulation header; ROS 1 packs them.
class WireReader {
 public:
  WireReader(const std::vector<std::uint8_t>& bytes, Wire wire) : bytes_(bytes), wire_(wire) {}

  // CDR: the encapsulation header (little-endian plain CDR only).
  Status Begin() {
    if (wire_ == Wire::kRos1) return Status::Ok();
    if (bytes_.size() < 4) return Status::DataLoss("message ends inside its CDR header");
    if (bytes_[0] != 0 || bytes_[1] != 1) {
      return Status::DataLoss("CDR encapsulation " + std::to_string(bytes_[0]) + "," + std::to_string(bytes_[1]) +
                              " is not little-endian CDR (0,1), the only one read");
    }
    position_ = 4;
    origin_ = 4;
    return Status::Ok();
  }

  template <typename T>
  Status Read(const char* field, T* value) {
    Align(sizeof(T));
    if (position_ + sizeof(T) > bytes_.size()) return Status::DataLoss(std::string("message ends inside ") + field);
    std::memcpy(value, bytes_.data() + position_, sizeof(T));
    position_ += sizeof(T);
    return Status::Ok();
  }

  Status ReadFinite(const char* field, double* value) {
    PATROLMAP_RETURN_IF_ERROR(Read(field, value));
    if (!std::isfinite(*value)) return Status::DataLoss(std::string(field) + " is not a finite number");
    return Status::Ok();
  }

  template <std::size_t N>
  Status ReadDoubles(const char* field, std::array<double, N>* values) {
    for (double& value : *values) PATROLMAP_RETURN_IF_ERROR(Read(field, &value));
    return Status::Ok();
  }

  Status ReadVector(const char* field, Eigen::Vector3d* vector) {
    for (int i = 0; i < 3; ++i) PATROLMAP_RETURN_IF_ERROR(ReadFinite(field, &(*vector)[i]));
    return Status::Ok();
  }

  // geometry_msgs/Quaternion: x, y, z, w; normalised, and refused when it has no length.
  Status ReadQuaternion(const char* field, Eigen::Quaterniond* rotation) {
    double x = 0, y = 0, z = 0, w = 0;
    for (double* value : {&x, &y, &z, &w}) PATROLMAP_RETURN_IF_ERROR(ReadFinite(field, value));
    const double largest = std::max({std::abs(x), std::abs(y), std::abs(z), std::abs(w)});
    if (!(largest > 1e-6)) return Status::DataLoss(std::string(field) + " is not a rotation (zero length)");
    // Huge components are scaled down first so that the norm does not overflow; others are normalised as
    // they are, as the EuRoC reader does, so both give the same poses to the bit.
    const double scale = largest > 1e100 ? largest : 1.0;
    *rotation = Eigen::Quaterniond(w / scale, x / scale, y / scale, z / scale);
    rotation->normalize();
    return Status::Ok();
  }

  Status ReadString(const char* field, std::string* text) {
    std::uint32_t length = 0;
    PATROLMAP_RETURN_IF_ERROR(ReadLength(field, 1, &length));
    const char* begin = reinterpret_cast<const char*>(bytes_.data() + position_);
    position_ += length;
    if (wire_ == Wire::kCdr && length > 0) --length;  // CDR counts the terminating NUL
    if (length > kMaxStringBytes) return Status::DataLoss(std::string(field) + " is longer than 64 KB");
    text->assign(begin, length);
    return Status::Ok();
  }

  // A sequence's element count, checked against the bytes left for `element_size` bytes each (at least: the
  // first element's alignment is read with it).
  Status ReadLength(const char* field, std::size_t element_size, std::uint32_t* count) {
    PATROLMAP_RETURN_IF_ERROR(Read(field, count));
    if (static_cast<std::uint64_t>(*count) * element_size > bytes_.size() - position_) {
      return Status::DataLoss(std::string("message ends inside ") + field + " (" + std::to_string(*count) +
                              " elements declared)");
    }
    return Status::Ok();
  }

  // A uint8 sequence: its bytes stay in the message.
  Status ReadBytes(const char* field, const std::uint8_t** data, std::size_t* size) {
    std::uint32_t count = 0;
    PATROLMAP_RETURN_IF_ERROR(ReadLength(field, 1, &count));
    *data = bytes_.data() + position_;
    *size = count;
    position_ += count;
    return Status::Ok();
  }

  Status ReadHeader(Header* header) {
    if (wire_ == Wire::kRos1) {
      std::uint32_t sequence = 0;
      PATROLMAP_RETURN_IF_ERROR(Read("header.seq", &sequence));
      std::uint32_t seconds = 0, nanoseconds = 0;
      PATROLMAP_RETURN_IF_ERROR(Read("header.stamp", &seconds));
      PATROLMAP_RETURN_IF_ERROR(Read("header.stamp", &nanoseconds));
      header->stamp_ns = static_cast<TimestampNs>(seconds) * 1'000'000'000 + nanoseconds;
    } else {
      std::int32_t seconds = 0;
      std::uint32_t nanoseconds = 0;
      PATROLMAP_RETURN_IF_ERROR(Read("header.stamp", &seconds));
      PATROLMAP_RETURN_IF_ERROR(Read("header.stamp", &nanoseconds));
      header->stamp_ns = static_cast<TimestampNs>(seconds) * 1'000'000'000 + nanoseconds;
    }
    if (header->stamp_ns < 0) return Status::DataLoss("header.stamp is before 1970");
    return ReadString("header.frame_id", &header->frame_id);
  }

  Status ReadPose(Eigen::Vector3d* position, Eigen::Quaterniond* rotation) {
    PATROLMAP_RETURN_IF_ERROR(ReadVector("pose.position", position));
    return ReadQuaternion("pose.orientation", rotation);
  }

  // The data ends a message: bytes past it (beyond CDR's padding to 4 bytes) mean the bytes hold another type.
  Status End(const char* what) const {
    const std::size_t padding = wire_ == Wire::kCdr ? 3 : 0;
    if (bytes_.size() > position_ + padding) {
      return Status::DataLoss("the message does not hold " + std::string(what) + ": " +
                              std::to_string(bytes_.size() - position_) + " bytes follow its data");
    }
    return Status::Ok();
  }

  Status Skip(const char* field, std::size_t element_size, std::size_t count) {
    Align(element_size);
    if (position_ + element_size * count > bytes_.size()) {
      return Status::DataLoss(std::string("message ends inside ") + field);
    }
    position_ += element_size * count;
    return Status::Ok();
  }

 private:
  void Align(std::size_t size) {
    if (wire_ == Wire::kCdr && size > 1) position_ = origin_ + (position_ - origin_ + size - 1) / size * size;
  }

  const std::vector<std::uint8_t>& bytes_;
  Wire wire_;
  std::size_t position_ = 0;
  std::size_t origin_ = 0;
};

}  // namespace

MessageKind KindOfType(const std::string& type) {
  std::string name = type;
  const std::size_t msg = name.find("/msg/");
  if (msg != std::string::npos) name.erase(msg, 4);
  if (name == "sensor_msgs/Image") return MessageKind::kImage;
  if (name == "sensor_msgs/CompressedImage") return MessageKind::kCompressedImage;
  if (name == "sensor_msgs/Imu") return MessageKind::kImu;
  if (name == "sensor_msgs/NavSatFix") return MessageKind::kNavSatFix;
  if (name == "geometry_msgs/PoseStamped") return MessageKind::kPoseStamped;
  if (name == "geometry_msgs/PoseWithCovarianceStamped") return MessageKind::kPoseWithCovarianceStamped;
  if (name == "nav_msgs/Odometry") return MessageKind::kOdometry;
  if (name == "sensor_msgs/CameraInfo") return MessageKind::kCameraInfo;
  if (name == "tf2_msgs/TFMessage") return MessageKind::kTransforms;
  return MessageKind::kOther;
}

Status DecodeImage(const std::vector<std::uint8_t>& bytes, Wire wire, bool compressed, ImageMessage* message) {
  WireReader reader(bytes, wire);
  PATROLMAP_RETURN_IF_ERROR(reader.Begin());
  PATROLMAP_RETURN_IF_ERROR(reader.ReadHeader(&message->header));
  message->compressed = compressed;
  if (compressed) {
    PATROLMAP_RETURN_IF_ERROR(reader.ReadString("format", &message->encoding));
    PATROLMAP_RETURN_IF_ERROR(reader.ReadBytes("data", &message->data, &message->size));
    return reader.End("a compressed image");
  }
  PATROLMAP_RETURN_IF_ERROR(reader.Read("height", &message->height));
  PATROLMAP_RETURN_IF_ERROR(reader.Read("width", &message->width));
  PATROLMAP_RETURN_IF_ERROR(reader.ReadString("encoding", &message->encoding));
  std::uint8_t big_endian = 0;
  PATROLMAP_RETURN_IF_ERROR(reader.Read("is_bigendian", &big_endian));
  message->big_endian = big_endian != 0;
  PATROLMAP_RETURN_IF_ERROR(reader.Read("step", &message->step));
  PATROLMAP_RETURN_IF_ERROR(reader.ReadBytes("data", &message->data, &message->size));
  return reader.End("an image");
}

Status DecodeImu(const std::vector<std::uint8_t>& bytes, Wire wire, ImuMessage* message) {
  WireReader reader(bytes, wire);
  PATROLMAP_RETURN_IF_ERROR(reader.Begin());
  PATROLMAP_RETURN_IF_ERROR(reader.ReadHeader(&message->header));
  std::array<double, 4> q{};  // x, y, z, w
  PATROLMAP_RETURN_IF_ERROR(reader.ReadDoubles("orientation", &q));
  std::array<double, 9> covariance{};
  PATROLMAP_RETURN_IF_ERROR(reader.ReadDoubles("orientation_covariance", &covariance));
  const double length = std::sqrt(q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3]);
  message->orientation.reset();
  if (covariance[0] != -1.0 && std::isfinite(length) && std::abs(length - 1.0) < 1e-3) {
    message->orientation = Eigen::Quaterniond(q[3], q[0], q[1], q[2]).normalized();
  }
  PATROLMAP_RETURN_IF_ERROR(reader.ReadVector("angular_velocity", &message->gyro));
  PATROLMAP_RETURN_IF_ERROR(reader.Skip("angular_velocity_covariance", sizeof(double), 9));
  PATROLMAP_RETURN_IF_ERROR(reader.ReadVector("linear_acceleration", &message->accel));
  return reader.Skip("linear_acceleration_covariance", sizeof(double), 9);
}

Status DecodeNavSatFix(const std::vector<std::uint8_t>& bytes, Wire wire, NavSatFixMessage* message) {
  WireReader reader(bytes, wire);
  PATROLMAP_RETURN_IF_ERROR(reader.Begin());
  PATROLMAP_RETURN_IF_ERROR(reader.ReadHeader(&message->header));
  std::int8_t status = 0;
  std::uint16_t service = 0;
  PATROLMAP_RETURN_IF_ERROR(reader.Read("status.status", &status));
  PATROLMAP_RETURN_IF_ERROR(reader.Read("status.service", &service));
  message->status = status;
  PATROLMAP_RETURN_IF_ERROR(reader.ReadVector("latitude, longitude, altitude", &message->position));
  if (std::abs(message->position.x()) > 90.0 || std::abs(message->position.y()) > 180.0) {
    return Status::DataLoss("latitude must lie in [-90, 90] and longitude in [-180, 180] degrees");
  }
  return Status::Ok();
}

Status DecodePose(const std::vector<std::uint8_t>& bytes, Wire wire, MessageKind kind, PoseMessage* message) {
  WireReader reader(bytes, wire);
  PATROLMAP_RETURN_IF_ERROR(reader.Begin());
  PATROLMAP_RETURN_IF_ERROR(reader.ReadHeader(&message->header));
  if (kind == MessageKind::kOdometry)
    PATROLMAP_RETURN_IF_ERROR(reader.ReadString("child_frame_id", &message->child_frame));
  PATROLMAP_RETURN_IF_ERROR(reader.ReadPose(&message->position, &message->rotation));
  if (kind != MessageKind::kOdometry) return Status::Ok();
  PATROLMAP_RETURN_IF_ERROR(reader.Skip("pose.covariance", sizeof(double), 36));
  PATROLMAP_RETURN_IF_ERROR(reader.ReadVector("twist.linear", &message->velocity));
  message->has_velocity = true;
  return Status::Ok();
}

Status DecodeCameraInfo(const std::vector<std::uint8_t>& bytes, Wire wire, CameraInfoMessage* message) {
  WireReader reader(bytes, wire);
  PATROLMAP_RETURN_IF_ERROR(reader.Begin());
  PATROLMAP_RETURN_IF_ERROR(reader.ReadHeader(&message->header));
  PATROLMAP_RETURN_IF_ERROR(reader.Read("height", &message->height));
  PATROLMAP_RETURN_IF_ERROR(reader.Read("width", &message->width));
  PATROLMAP_RETURN_IF_ERROR(reader.ReadString("distortion_model", &message->distortion_model));
  std::uint32_t count = 0;
  PATROLMAP_RETURN_IF_ERROR(reader.ReadLength("D", sizeof(double), &count));
  message->distortion.resize(count);
  for (double& value : message->distortion) PATROLMAP_RETURN_IF_ERROR(reader.Read("D", &value));
  PATROLMAP_RETURN_IF_ERROR(reader.ReadDoubles("K", &message->k));
  PATROLMAP_RETURN_IF_ERROR(reader.ReadDoubles("R", &message->r));
  return reader.ReadDoubles("P", &message->p);
}

Status DecodeTransforms(const std::vector<std::uint8_t>& bytes, Wire wire, std::vector<TransformMessage>* transforms) {
  WireReader reader(bytes, wire);
  PATROLMAP_RETURN_IF_ERROR(reader.Begin());
  std::uint32_t count = 0;
  // The smallest transform: an empty header and child and 7 numbers.
  PATROLMAP_RETURN_IF_ERROR(reader.ReadLength("transforms", 7 * sizeof(double), &count));
  transforms->resize(count);
  for (TransformMessage& transform : *transforms) {
    PATROLMAP_RETURN_IF_ERROR(reader.ReadHeader(&transform.header));
    PATROLMAP_RETURN_IF_ERROR(reader.ReadString("child_frame_id", &transform.child_frame));
    PATROLMAP_RETURN_IF_ERROR(reader.ReadVector("transform.translation", &transform.translation));
    PATROLMAP_RETURN_IF_ERROR(reader.ReadQuaternion("transform.rotation", &transform.rotation));
  }
  return Status::Ok();
}

}  // namespace patrolmap::io::rosmsg
