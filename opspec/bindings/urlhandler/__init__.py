"""pySerial URL handlers provided by opspec (found through ``serial.protocol_handler_packages``)."""
