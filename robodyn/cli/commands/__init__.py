"""One module a command: ``add_parser(commands)`` declares its arguments, ``run(arguments)`` calls the library and returns the exit status."""
