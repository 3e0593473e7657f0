# Generates a C++ source holding Chart.js (Debian's libjs-chart.js) as text, so that kin2grf's
# HTML reports are self-contained: the browser needs no network to draw them.
file(READ "${CHARTJS}" text)
string(LENGTH "${text}" len)
set(content "// Generated from ${CHARTJS} by cmake/embed_chartjs.cmake. Do not edit.\n// Chart.js (MIT licence, https://www.chartjs.org), packaged by Debian as libjs-chart.js.\n#include <string>\nnamespace kin2grf {\nconst std::string& chartjs_source() {\n  static const std::string s = std::string()\n")
set(pos 0)
while(pos LESS len)
  string(SUBSTRING "${text}" ${pos} 8000 chunk)
  string(APPEND content "    + R\"kin2grfjs(${chunk})kin2grfjs\"\n")
  math(EXPR pos "${pos} + 8000")
endwhile()
string(APPEND content "  ;\n  return s;\n}\n}  // namespace kin2grf\n")
file(WRITE "${OUTPUT}.tmp" "${content}")
execute_process(COMMAND ${CMAKE_COMMAND} -E copy_if_different "${OUTPUT}.tmp" "${OUTPUT}")
