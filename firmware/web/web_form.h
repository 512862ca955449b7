// The page's form bodies (application/x-www-form-urlencoded, decoded by libmicrohttpd's post
// processor in web_server.cc) and the refocus choice read from one: no HTTP here, so the rules
// are tested on their own (tests/firmware/web/web_form_test.cc).
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>

#include "algo/core/status.h"
#include "firmware/web/refocus_backend.h"

namespace lb {

// The decoded fields of one body, as the post processor hands them over: a value may come in
// pieces.
struct Fields {
  static constexpr int kMax = 12;
  std::string key[kMax], value[kMax];
  int count = 0;

  // The value of `name`, or nullptr.
  const char* Get(const char* name) const;
  // Adds key `k` when `offset` is 0, else continues its value from `offset`. False (the body
  // is refused) past kMax fields, for a piece that does not continue the last field, and for a
  // decoded NUL, which would cut the text the checks see short of what was sent.
  bool Add(const char* k, const char* data, uint64_t offset, size_t size);
  // Adds, with an empty value, each field of the raw form `body` that has none ("f=" or "f"),
  // which the post processor reports not at all; a name is percent-decoded by the library. False
  // past kMax fields.
  bool AddEmpty(const char* body, size_t size);
};

// The page's choice from a preview, render or save body: name, x0 and y0 (0..1 of the displayed
// photo), x1 and y1 (default x0 and y0: a tap; a drag is put in order), f (an f-number in
// RenderParams' range) and blades (0: a disc, or 3..12). Absent, an optional field takes its
// default; sent empty, it is refused like any bad value. kInvalidArgument says which is wrong.
Status ParseRefocus(const Fields& f, std::string* name, RefocusParams* p);

}  // namespace lb
