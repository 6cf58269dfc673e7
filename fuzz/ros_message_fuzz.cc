// Fuzzes the decoders of ROS bag messages (src/io/bag_messages.h): the first byte chooses the wire format
// (bit 0: CDR) and the message type (the rest), the remaining bytes are the message.
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <vector>

#include "io/bag_messages.h"

namespace rosmsg = patrolmap::io::rosmsg;

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size == 0) return 0;
  const rosmsg::Wire wire = (data[0] & 1) != 0 ? rosmsg::Wire::kCdr : rosmsg::Wire::kRos1;
  const std::vector<std::uint8_t> bytes(data + 1, data + size);
  switch ((data[0] >> 1) % 6) {
    case 0: {
      rosmsg::ImageMessage image;
      if (rosmsg::DecodeImage(bytes, wire, (data[0] & 0x80) != 0, &image).ok()) {
        // The pixels lie inside the message.
        if (image.data < bytes.data() || image.data + image.size > bytes.data() + bytes.size()) __builtin_trap();
      }
      break;
    }
    case 1: {
      rosmsg::ImuMessage imu;
      if (rosmsg::DecodeImu(bytes, wire, &imu).ok() && !(imu.gyro.allFinite() && imu.accel.allFinite())) {
        __builtin_trap();
      }
      break;
    }
    case 2: {
      rosmsg::NavSatFixMessage fix;
      if (rosmsg::DecodeNavSatFix(bytes, wire, &fix).ok() && !(std::abs(fix.position.x()) <= 90.0)) __builtin_trap();
      break;
    }
    case 3: {
      rosmsg::PoseMessage pose;
      const auto kind = (data[0] & 0x80) != 0 ? rosmsg::MessageKind::kOdometry : rosmsg::MessageKind::kPoseStamped;
      if (rosmsg::DecodePose(bytes, wire, kind, &pose).ok() && !(std::abs(pose.rotation.norm() - 1.0) < 1e-6)) {
        __builtin_trap();
      }
      break;
    }
    case 4: {
      rosmsg::CameraInfoMessage info;
      (void)rosmsg::DecodeCameraInfo(bytes, wire, &info);
      break;
    }
    default: {
      std::vector<rosmsg::TransformMessage> transforms;
      (void)rosmsg::DecodeTransforms(bytes, wire, &transforms);
    }
  }
  return 0;
}
