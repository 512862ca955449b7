// XMP lookups over a packet's text, without copying it (no allocation): a field is an attribute
// prefix:name="value" or a simple element <prefix:name>value</prefix:name>, the prefix the one an
// xmlns attribute binds to the namespace (none bound: nothing matches). Shared by the GDepth and
// the Dynamic Depth readers.
#pragma once

#include <cstddef>
#include <string_view>

namespace lb {

bool IsXmpSpace(char c);

// A decimal number with optional surrounding spaces, finite.
bool ParseXmpNumber(std::string_view text, double* out);

// The prefix an xmlns attribute anywhere in `text` binds to `uri` ("" when none does).
std::string_view XmpPrefixOf(std::string_view text, std::string_view uri);

// The value of `prefix`:`name` in `text`, the prefix already resolved.
bool FindXmpFieldByPrefix(std::string_view text, std::string_view prefix, std::string_view name,
                          std::string_view* value);

// The value of the field `name` of the namespace `uri`, the prefix bound in `text` itself.
bool FindXmpField(std::string_view text, std::string_view uri, std::string_view name,
                  std::string_view* value);

// The element <prefix:name ...> starting at or after `from`: `*element` is the text from its
// opening "<" to the end of its closing tag (or of its own tag when it closes itself) and
// `*next` where a search for the next one goes on. False when there is none, or when it is not
// closed.
bool FindXmpElement(std::string_view text, std::string_view prefix, std::string_view name,
                    size_t from, std::string_view* element, size_t* next);

}  // namespace lb
