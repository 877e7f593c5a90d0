# Read by cpack while it packages (CPACK_PROJECT_CONFIG_FILE, cmake/Packaging.cmake): the install
# it runs then includes the Python package whatever ROUGHSCOPE_INSTALL_PYTHON says.
set(ENV{ROUGHSCOPE_CPACK} 1)
