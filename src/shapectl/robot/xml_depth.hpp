#pragma once
// How deep XML elements nest, checked before TinyXML parses the text: TinyXML recurses once per
// nested element, so a hostile file could otherwise overflow the stack.
#include <cstddef>
#include <string_view>

namespace shapectl {

inline constexpr int max_xml_depth = 100;

// Where `xml` nests elements deeper than `max_depth` (byte offset), or npos. One pass, no
// recursion: skips comments, CDATA, declarations and quoted attribute values.
std::size_t xml_too_deep_at(std::string_view xml, int max_depth);

}  // namespace shapectl
