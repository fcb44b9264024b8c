# placeholder, replaced by the foundation work
message(STATUS "consumer test not yet written")
