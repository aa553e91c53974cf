// printf-style formatting into a std::string, for the summary lines.
#pragma once
#include <cstdio>
#include <string>

namespace partet {

template <class... Values>
std::string format(const char* pattern, Values... values) {
  char text[256];
  std::snprintf(text, sizeof text, pattern, values...);
  return text;
}

}  // namespace partet
