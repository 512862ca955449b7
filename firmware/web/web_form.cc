#include "firmware/web/web_form.h"

#include <microhttpd.h>

#include <cmath>
#include <cstdlib>
#include <cstring>
#include <utility>

namespace lb {
namespace {

bool Number(const char* text, float lo, float hi, float* out) {
  if (text == nullptr || *text == '\0') return false;
  char* end = nullptr;
  const float v = strtof(text, &end);
  if (*end != '\0' || !std::isfinite(v) || v < lo || v > hi) return false;
  *out = v;
  return true;
}

}  // namespace

const char* Fields::Get(const char* name) const {
  for (int i = 0; i < count; ++i) {
    if (key[i] == name) return value[i].c_str();
  }
  return nullptr;
}

bool Fields::Add(const char* k, const char* data, uint64_t offset, size_t size) {
  if (memchr(data, '\0', size) != nullptr) return false;
  if (offset == 0) {
    if (count == kMax) return false;
    key[count] = k;
    value[count].clear();
    ++count;
  } else if (count == 0 || key[count - 1] != k || value[count - 1].size() != offset) {
    return false;
  }
  value[count - 1].append(data, size);
  return true;
}

bool Fields::AddEmpty(const char* body, size_t size) {
  for (size_t i = 0; i < size;) {
    size_t end = i;
    while (end < size && body[end] != '&') ++end;
    size_t key_end = i;
    while (key_end < end && body[key_end] != '=') ++key_end;
    if (key_end > i && key_end + 1 >= end) {
      std::string k(body + i, key_end - i);
      for (char& ch : k) ch = ch == '+' ? ' ' : ch;
      k.resize(MHD_http_unescape(k.data()));
      if (Get(k.c_str()) == nullptr) {
        if (count == kMax) return false;
        key[count] = k;
        value[count].clear();
        ++count;
      }
    }
    i = end + 1;
  }
  return true;
}

Status ParseRefocus(const Fields& f, std::string* name, RefocusParams* p) {
  static const struct {
    const char* key;
    bool optional;
  } kFields[] = {{"name", false}, {"x0", false}, {"y0", false},   {"x1", true},
                 {"y1", true},    {"f", true},   {"blades", true}};
  for (const auto& field : kFields) {
    const char* v = f.Get(field.key);
    if (v != nullptr && *v == '\0') {
      return Status(Code::kInvalidArgument, "%s is empty%s", field.key,
                    field.optional ? ": give it a value or leave it out" : "");
    }
  }
  const char* n = f.Get("name");
  if (n == nullptr) return Status(Code::kInvalidArgument, "the body names no photo (name=)");
  *name = n;
  if (!Number(f.Get("x0"), 0.0f, 1.0f, &p->x0) || !Number(f.Get("y0"), 0.0f, 1.0f, &p->y0)) {
    return Status(Code::kInvalidArgument, "x0 and y0 must be numbers from 0 to 1");
  }
  p->x1 = p->x0;
  p->y1 = p->y0;
  if ((f.Get("x1") != nullptr && !Number(f.Get("x1"), 0.0f, 1.0f, &p->x1)) ||
      (f.Get("y1") != nullptr && !Number(f.Get("y1"), 0.0f, 1.0f, &p->y1))) {
    return Status(Code::kInvalidArgument, "x1 and y1 must be numbers from 0 to 1");
  }
  if (p->x1 < p->x0) std::swap(p->x0, p->x1);
  if (p->y1 < p->y0) std::swap(p->y0, p->y1);
  if (f.Get("f") != nullptr &&
      !Number(f.Get("f"), RenderParams::kMinFNumber, RenderParams::kMaxFNumber, &p->f_number)) {
    return Status(Code::kInvalidArgument, "f must be an f-number from %g to %g",
                  static_cast<double>(RenderParams::kMinFNumber),
                  static_cast<double>(RenderParams::kMaxFNumber));
  }
  float blades = 0.0f;
  if (f.Get("blades") != nullptr) {
    if (!Number(f.Get("blades"), 0.0f, 12.0f, &blades) || blades != std::floor(blades) ||
        (blades > 0.0f && blades < 3.0f)) {
      return Status(Code::kInvalidArgument, "blades must be 0 (a disc) or 3 to 12");
    }
  }
  p->aperture.blades = static_cast<int32_t>(blades);
  return Status::Ok();
}

}  // namespace lb
