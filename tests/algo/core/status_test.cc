#include "algo/core/status.h"

#include <gtest/gtest.h>

#include <string>

namespace lb {
namespace {

Status Fails() { return Status(Code::kCorruptData, "%s: bad header at byte %d", "a.ppm", 12); }
Status Propagates() {
  LB_RETURN_IF_ERROR(Fails());
  return Status::Ok();
}

TEST(Status, CarriesCodeAndFormattedMessage) {
  Status s = Propagates();
  EXPECT_FALSE(s.ok());
  EXPECT_EQ(s.code(), Code::kCorruptData);
  EXPECT_STREQ(s.message(), "a.ppm: bad header at byte 12");
  s.Prefix("frame %d: ", 3);
  EXPECT_STREQ(s.message(), "frame 3: a.ppm: bad header at byte 12");
  EXPECT_TRUE(Status::Ok().ok());
}

TEST(Status, LongMessagesAreTruncatedNotOverrun) {
  std::string long_name(1000, 'x');
  Status s(Code::kNotFound, "%s", long_name.c_str());
  EXPECT_EQ(std::string(s.message()).size(), Status::kMaxMessage - 1);
}

}  // namespace
}  // namespace lb
