#include "firmware/refocusable/xmp_lookup.h"

#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <cstring>

namespace lb {
namespace {

bool Quoted(std::string_view text, size_t pos, std::string_view* value) {
  while (pos < text.size() && IsXmpSpace(text[pos])) ++pos;
  if (pos >= text.size() || (text[pos] != '"' && text[pos] != '\'')) return false;
  const size_t end = text.find(text[pos], pos + 1);
  if (end == std::string_view::npos) return false;
  *value = text.substr(pos + 1, end - pos - 1);
  return true;
}

// Whether `text` at `pos` holds prefix:name with at least one character after it.
bool NameAt(std::string_view text, size_t pos, std::string_view prefix, std::string_view name) {
  const size_t end = pos + prefix.size() + 1 + name.size();
  return end < text.size() && text.substr(pos, prefix.size()) == prefix &&
         text[pos + prefix.size()] == ':' &&
         text.substr(pos + prefix.size() + 1, name.size()) == name;
}

}  // namespace

bool IsXmpSpace(char c) { return c == ' ' || c == '\t' || c == '\r' || c == '\n'; }

bool ParseXmpNumber(std::string_view v, double* out) {
  while (!v.empty() && IsXmpSpace(v.front())) v.remove_prefix(1);
  while (!v.empty() && IsXmpSpace(v.back())) v.remove_suffix(1);
  char text[64];
  if (v.empty() || v.size() >= sizeof(text)) return false;
  memcpy(text, v.data(), v.size());
  text[v.size()] = '\0';
  char* end = nullptr;
  errno = 0;
  *out = strtod(text, &end);
  return end == text + v.size() && errno == 0 && std::isfinite(*out);
}

std::string_view XmpPrefixOf(std::string_view text, std::string_view uri) {
  size_t pos = 0;
  while ((pos = text.find("xmlns:", pos)) != std::string_view::npos) {
    pos += 6;
    const size_t eq = text.find('=', pos);
    if (eq == std::string_view::npos || eq - pos > 64) continue;
    size_t end = eq;
    while (end > pos && IsXmpSpace(text[end - 1])) --end;
    std::string_view value;
    if (Quoted(text, eq + 1, &value) && value == uri) return text.substr(pos, end - pos);
  }
  return {};
}

bool FindXmpFieldByPrefix(std::string_view text, std::string_view prefix, std::string_view name,
                          std::string_view* value) {
  if (prefix.empty()) return false;
  const size_t qsize = prefix.size() + 1 + name.size();
  size_t pos = 0;
  while ((pos = text.find(prefix, pos)) != std::string_view::npos) {
    const size_t start = pos, after = pos + qsize;
    pos += prefix.size();
    if (start == 0 || !NameAt(text, start, prefix, name)) continue;
    const bool element = text[start - 1] == '<';
    if (!element && !IsXmpSpace(text[start - 1])) continue;  // part of a longer name
    if (element) {
      if (text[after] != '>') continue;
      size_t close = after + 1;
      while ((close = text.find("</", close)) != std::string_view::npos) {
        if (text.substr(close + 2, qsize) == text.substr(start, qsize)) break;
        close += 2;
      }
      if (close == std::string_view::npos) return false;
      *value = text.substr(after + 1, close - after - 1);
      return true;
    }
    size_t eq = after;
    while (eq < text.size() && IsXmpSpace(text[eq])) ++eq;
    if (eq >= text.size() || text[eq] != '=') continue;
    return Quoted(text, eq + 1, value);
  }
  return false;
}

bool FindXmpField(std::string_view text, std::string_view uri, std::string_view name,
                  std::string_view* value) {
  return FindXmpFieldByPrefix(text, XmpPrefixOf(text, uri), name, value);
}

bool FindXmpElement(std::string_view text, std::string_view prefix, std::string_view name,
                    size_t from, std::string_view* element, size_t* next) {
  if (prefix.empty()) return false;
  size_t pos = from;
  while ((pos = text.find('<', pos)) != std::string_view::npos) {
    const size_t start = pos++;
    if (!NameAt(text, start + 1, prefix, name)) continue;
    const char c = text[start + 2 + prefix.size() + name.size()];
    if (c != '>' && c != '/' && !IsXmpSpace(c)) continue;  // a longer name
    // The end of the opening tag, past any quoted value that holds a '>'.
    size_t end = start + 1;
    char quote = 0;
    for (; end < text.size(); ++end) {
      if (quote != 0) {
        if (text[end] == quote) quote = 0;
      } else if (text[end] == '"' || text[end] == '\'') {
        quote = text[end];
      } else if (text[end] == '>') {
        break;
      }
    }
    if (end >= text.size()) return false;
    if (text[end - 1] == '/') {
      *element = text.substr(start, end + 1 - start);
      *next = end + 1;
      return true;
    }
    size_t close = end;
    while ((close = text.find("</", close)) != std::string_view::npos) {
      if (NameAt(text, close + 2, prefix, name) &&
          text[close + 3 + prefix.size() + name.size()] == '>') {
        break;
      }
      close += 2;
    }
    if (close == std::string_view::npos) return false;
    const size_t stop = close + 4 + prefix.size() + name.size();
    *element = text.substr(start, stop - start);
    *next = stop;
    return true;
  }
  return false;
}

}  // namespace lb
