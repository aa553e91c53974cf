// Text inside the XML files partet writes (.pvtu, .xdmf): file names there must be escaped, or a
// name with '&' or '<' makes the file unreadable (ParaView read no cells from such a .pvtu).
#pragma once
#include <string>

namespace partet {

inline std::string xml_escaped(const std::string& text) {
  std::string out;
  for (char c : text) {
    switch (c) {
      case '&':
        out += "&amp;";
        break;
      case '<':
        out += "&lt;";
        break;
      case '>':
        out += "&gt;";
        break;
      case '"':
        out += "&quot;";
        break;
      case '\'':
        out += "&apos;";
        break;
      default:
        out += c;
    }
  }
  return out;
}

// The five entities xml_escaped writes, back to their characters (others are left as they are).
inline std::string xml_unescaped(const std::string& text) {
  static const std::pair<const char*, char> kEntities[] = {
      {"&amp;", '&'}, {"&lt;", '<'}, {"&gt;", '>'}, {"&quot;", '"'}, {"&apos;", '\''}};
  std::string out;
  for (std::size_t at = 0; at < text.size();) {
    bool replaced = false;
    for (const auto& [entity, c] : kEntities)
      if (text.compare(at, std::char_traits<char>::length(entity), entity) == 0) {
        out += c, at += std::char_traits<char>::length(entity), replaced = true;
        break;
      }
    if (!replaced) out += text[at++];
  }
  return out;
}

}  // namespace partet
