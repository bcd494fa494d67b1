"""Options shared by the whole test suite come from the opspec pytest plugin
(``opspec.testing.plugin``, registered through the ``pytest11`` entry point).

``--device-url`` (and ``--device-profile``) run the hardware-in-the-loop tests marked
``@pytest.mark.hardware`` against a real device: ``pytest --device-url=/dev/ttyUSB0 -m hardware``.
Without ``--device-url`` those tests are skipped with a message saying how to run them.
"""
