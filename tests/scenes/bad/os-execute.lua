-- a scene that tries to run a command
os.execute("touch /tmp/shadowlab-pwned")
return {}
